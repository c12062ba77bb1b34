// The GNSS fixes' innovations as the filter fused them, for post-processing: what a user reads
// the fix's error model from (its horizontal sigma and correlation time, docs/real_data.md 6b)
// and where the consistency monitor's alarms come from. Not on the bus.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace navbus::core {

/// One fused fix: z - H x = predicted - measured (aiding_measurements.hpp) per NED row, as the
/// sequential update met it (after the rows before it), and sqrt(H P H^T + R) of that row.
struct FixInnovation {
  std::int64_t time_ns{0};                              ///< the state's time the fix was fused at
  Eigen::Vector3d position_m{Eigen::Vector3d::Zero()};  ///< [m, NED]
  Eigen::Vector3d position_sigma_m{Eigen::Vector3d::Zero()};    ///< [m, NED]
  Eigen::Vector3d velocity_mps{Eigen::Vector3d::Zero()};        ///< [m/s, NED]
  Eigen::Vector3d velocity_sigma_mps{Eigen::Vector3d::Zero()};  ///< [m/s, NED]
  Eigen::Vector3d filter_vel_ned_mps{Eigen::Vector3d::Zero()};  ///< after the update: the track
  bool consistent{true};  ///< the consistency monitor's verdict on the window ending here
};

/// The fused fixes in time order. A filter restored to an earlier snapshot (a rewind) fuses
/// again from there: add() drops what the abandoned pass recorded at or after the new record.
class FixInnovationLog {
 public:
  void add(const FixInnovation& f);
  const std::vector<FixInnovation>& records() const { return records_; }
  std::uint64_t dropped() const { return dropped_; }  ///< records of abandoned passes

 private:
  std::vector<FixInnovation> records_;
  std::uint64_t dropped_{0};
};

}  // namespace navbus::core
