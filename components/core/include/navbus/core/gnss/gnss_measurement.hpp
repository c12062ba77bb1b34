// Pseudorange and pseudorange-rate measurement model of the tightly coupled filter
// (seed 000 eq. 5): predictions from the INS state and clock estimates, and the rows of H
// over the error vector of state_layout.hpp.
#pragma once

#include <Eigen/Core>

#include "navbus/core/ins/state_layout.hpp"
#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

/// Satellites the filter processes per epoch at most (the diagnostics and the GLR are sized
/// for it).
inline constexpr int kMaxEpochSatellites = 24;

/// One satellite's corrected measurements (satellite clock applied, positions in the ECEF frame
/// of reception time, Sagnac applied).
struct SatelliteObservation {
  int sv_id{0};
  Eigen::Vector3d sat_pos_ecef_m{Eigen::Vector3d::Zero()};
  Eigen::Vector3d sat_vel_ecef_mps{Eigen::Vector3d::Zero()};
  double pseudorange_m{0.0};
  double pseudorange_rate_mps{0.0};
  double pseudorange_sigma_m{1.0};
  double pseudorange_rate_sigma_mps{0.1};
  bool use_range{true};  ///< false: the pseudorange is excluded (monitored, not fused)
  bool use_rate{true};   ///< false: the pseudorange rate is excluded
};

struct RangePrediction {
  double pseudorange_m;
  double pseudorange_rate_mps;
  Eigen::Vector3d los_ned;  ///< unit line of sight receiver -> satellite, NED at the receiver
  Eigen::Matrix<double, 1, layout::kSize> h_range;  ///< d(predicted - measured)/d(error state)
  Eigen::Matrix<double, 1, layout::kSize> h_rate;
};

/// Predicts the measurements of `sat` from the INS state and the clock estimates. With
/// error = estimate - truth, a predicted-minus-measured innovation z = H dx + noise, where
/// H_range = [-l^T 0 0 0 0 1 0] and H_rate = [0 -l^T 0 0 0 0 1] (l = line of sight in NED;
/// the rate's dependence on position through l is neglected, as in seed 000 eq. 5).
RangePrediction predictRange(const NavState& ins, double clock_bias_m, double clock_drift_mps,
                             const SatelliteObservation& sat);

}  // namespace navbus::core
