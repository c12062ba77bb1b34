// The increments of several IMU units aligned by their time (the fault manager's parity test,
// the filter's least-squares lane). Each unit's increments come in time order (one reliable
// reader instance per unit); the units' instances come in any order between them. A time is
// released when every unit has delivered it, or when a unit missing there has delivered a later
// time (it never will), or an ended unit is missing, or more than `depth` times wait (a silent
// unit): then incomplete, with the units present. Pure logic.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>

#include "navbus/core/ins/strapdown.hpp"

namespace navbus::bus {

class ImuUnitAligner {
 public:
  static constexpr int kMaxUnits = 6;
  using Increments = std::array<core::ImuIncrement, kMaxUnits>;

  struct Sample {
    std::int64_t time_ns{0};
    Increments units{};
    std::uint32_t present{0};  ///< bit per unit whose increment is in `units`
  };

  ImuUnitAligner(int units, std::size_t depth) : units_(units), depth_(depth) {}

  enum class Added { kTaken, kLate, kRepeated };
  /// Unit u's increment: kLate at or before the latest time released, kRepeated when that unit
  /// already gave this time.
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
  std::size_t waiting() const { return pending_.size(); }
  /// The latest time unit u delivered (0: none yet).
  std::int64_t latestNs(int unit) const { return latest_ns_[static_cast<std::size_t>(unit)]; }
  bool complete(const Sample& s) const { return s.present == all(); }

 private:
  static std::uint32_t bit(int unit) { return 1u << static_cast<unsigned>(unit); }
  std::uint32_t all() const { return (1u << static_cast<unsigned>(units_)) - 1u; }
  /// A unit missing at that time will not deliver it.
  bool lost(std::int64_t time_ns, std::uint32_t present) const;
  Sample take(std::map<std::int64_t, Sample>::iterator it);

  int units_;
  std::size_t depth_;
  std::map<std::int64_t, Sample> pending_;
  std::array<std::int64_t, kMaxUnits> latest_ns_{};
  std::uint32_t ended_{0};
  std::int64_t released_ns_{-1};
};

}  // namespace navbus::bus
