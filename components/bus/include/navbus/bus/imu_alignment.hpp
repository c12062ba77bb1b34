// The increments of several IMU units aligned by their time (the fault manager's parity test,
// the filter's least-squares lane). Each unit's increments come in time order (one reliable
// reader instance per unit); the units' instances come in any order between them: a reader hands
// out one unit's whole backlog before the next's (up to its history per instance: 5000 blocks of
// up to 128 increments, qos/navbus_qos.xml). A time is released when every unit has delivered it,
// or when a unit missing there has delivered a later time (it never will), or has ended, or one
// unit holds more than `depth` increments waiting (the missing one is silent): then incomplete,
// with the units present. Each unit's increments wait in a queue of their own (64 bytes each).
// Pure logic.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>

#include "navbus/bus/streams.hpp"
#include "navbus/core/ins/strapdown.hpp"

namespace navbus::bus {

class ImuUnitAligner {
 public:
  static constexpr int kMaxUnits = 6;
  /// Increments a reader may hand out of one unit before another's: its history per instance
  /// (5000 samples) of the largest blocks (kMaxIncrementsPerBlock).
  static constexpr std::size_t kReaderBacklog = 5000 * kMaxIncrementsPerBlock;
  using Increments = std::array<core::ImuIncrement, kMaxUnits>;

  struct Sample {
    std::int64_t time_ns{0};
    Increments units{};
    std::uint32_t present{0};  ///< bit per unit whose increment is in `units`
  };

  ImuUnitAligner(int units, std::size_t depth) : units_(units), depth_(depth) {}

  enum class Added { kTaken, kLate, kRepeated };
  /// Unit u's increment: kLate at or before the latest time released, kRepeated at or before
  /// that unit's latest (a repeated time, or one out of order).
  Added add(int unit, const core::ImuIncrement& inc);
  /// The oldest waiting time, taken out, once it is complete or will not be (see above); and
  /// only at or before `up_to_ns`.
  std::optional<Sample> next(std::int64_t up_to_ns = std::numeric_limits<std::int64_t>::max());
  /// The oldest waiting time whatever it waits for (the data ended).
  std::optional<Sample> flushNext();
  /// The unit's increments ended: it is no longer waited for.
  void endUnit(int unit) { ended_ |= bit(unit); }
  bool ended(int unit) const { return (ended_ & bit(unit)) != 0; }
  /// Forgets everything (a new run of the units' source).
  void clear();
  /// The latest time released (-1: none).
  std::int64_t releasedNs() const { return released_ns_; }
  /// The oldest time waiting (-1: none).
  std::int64_t oldestNs() const {
    std::uint32_t present = 0;
    return oldest(present);
  }
  /// The most increments one unit holds waiting.
  std::size_t waiting() const;
  /// The latest time unit u delivered (0: none yet).
  std::int64_t latestNs(int unit) const { return latest_ns_[static_cast<std::size_t>(unit)]; }
  bool complete(const Sample& s) const { return s.present == all(); }

 private:
  static std::uint32_t bit(int unit) { return 1u << static_cast<unsigned>(unit); }
  std::uint32_t all() const { return (1u << static_cast<unsigned>(units_)) - 1u; }
  /// The oldest time any unit holds (-1: none), and the units that hold it.
  std::int64_t oldest(std::uint32_t& present) const;
  /// A unit missing at that time will not deliver it.
  bool lost(std::int64_t time_ns, std::uint32_t present) const;
  Sample take(std::int64_t time_ns, std::uint32_t present);

  int units_;
  std::size_t depth_;
  std::array<std::deque<core::ImuIncrement>, kMaxUnits> queues_{};
  std::array<std::int64_t, kMaxUnits> latest_ns_{};
  std::uint32_t ended_{0};
  std::int64_t released_ns_{-1};
};

}  // namespace navbus::bus
