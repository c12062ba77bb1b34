// The velocity change the mechanization integrated over the last increments, so that a
// velocity measured earlier than the state's time can be brought to it: a receiver whose
// velocity lags its position (a velocity from differenced positions, or a filtered Doppler
// solution) measures v(t - tau); the state holds v(t); the INS says by how much v changed over
// [t - tau, t], from the specific force, without the filter's corrections in between (those
// correct the error, they are not motion). Fixed storage: copied with the engine's rollback
// snapshots without allocation.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace navbus::core {

class VelocityHistory {
 public:
  /// Increments remembered: 0.63 s at 100 Hz.
  static constexpr int kLength = 64;

  void clear() { count_ = 0; }
  /// The increment that ended at `time_ns` changed the velocity by `dv_ned_mps` [m/s, NED].
  void add(std::int64_t time_ns, const Eigen::Vector3d& dv_ned_mps) {
    const Eigen::Vector3d sum = count_ > 0 ? at(count_ - 1).cumulative + dv_ned_mps : dv_ned_mps;
    next_ = (next_ + 1) % kLength;
    entries_[static_cast<std::size_t>(next_)] = {time_ns, sum};
    if (count_ < kLength) ++count_;
  }
  /// The velocity change integrated from `from_ns` to the latest increment's end, linear within
  /// the increment holding `from_ns`, into `dv_ned_mps`; false (nothing written) when the
  /// history does not reach back that far or holds fewer than two increments.
  bool changeSince(std::int64_t from_ns, Eigen::Vector3d& dv_ned_mps) const {
    if (count_ < 2) return false;
    const Entry& latest = at(count_ - 1);
    if (from_ns >= latest.time_ns) {
      dv_ned_mps.setZero();
      return true;
    }
    for (int i = count_ - 2; i >= 0; --i) {
      const Entry& a = at(i);
      if (a.time_ns > from_ns) continue;
      const Entry& b = at(i + 1);
      const double w =
          static_cast<double>(from_ns - a.time_ns) / static_cast<double>(b.time_ns - a.time_ns);
      dv_ned_mps = latest.cumulative - ((1.0 - w) * a.cumulative + w * b.cumulative);
      return true;
    }
    return false;
  }

 private:
  struct Entry {
    std::int64_t time_ns{0};
    Eigen::Vector3d cumulative{Eigen::Vector3d::Zero()};  ///< sum of dv up to time_ns
  };
  /// Entry i from the oldest.
  const Entry& at(int i) const {
    return entries_[static_cast<std::size_t>((next_ - count_ + 1 + i + 2 * kLength) % kLength)];
  }
  std::array<Entry, kLength> entries_{};
  int count_{0};
  int next_{0};
};

}  // namespace navbus::core
