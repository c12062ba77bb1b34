// Pseudorange and pseudorange-rate measurement model of the tightly coupled filter
// (seed 000 eq. 5): predictions from the INS state and clock estimates, and the rows of H
// over the error vector of state_layout.hpp.
#pragma once

#include <array>

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
  /// Which fused receiver measured it (0: the first; its clock states are
  /// layout::clockBiasOf(receiver) and clockDriftOf(receiver)).
  int receiver{0};
};

struct RangePrediction {
  double pseudorange_m;
  double pseudorange_rate_mps;
  Eigen::Vector3d los_ned;  ///< unit line of sight receiver -> satellite, NED at the receiver
  Eigen::Matrix<double, 1, layout::kSize> h_range;  ///< d(predicted - measured)/d(error state)
  Eigen::Matrix<double, 1, layout::kSize> h_rate;
};

/// Where the antenna is from the IMU: the lever arm in body axes and the body's angular rate
/// relative to NED (which moves the antenna around the IMU). Zero: the antenna is at the IMU.
struct AntennaArm {
  Eigen::Vector3d lever_arm_b_m{Eigen::Vector3d::Zero()};
  Eigen::Vector3d rate_nb_b_radps{Eigen::Vector3d::Zero()};
};
/// Each fused receiver's antenna, in receiver order.
using AntennaArms = std::array<AntennaArm, layout::kMaxFusedReceivers>;

/// Predicts the measurements of `sat` at the antenna from the INS state and the clock
/// estimates. With error = estimate - truth, a predicted-minus-measured innovation
/// z = H dx + noise, where (seed 000 eq. 5, l = line of sight in NED, a = C_b_n lever the
/// antenna's offset in NED, b = C_b_n (w_nb x lever) its velocity about the IMU)
///   H_range: -l^T on the position error, -l^T [a x] on the attitude error, 1 on the clock bias;
///   H_rate:  -l^T on the velocity error, -l^T [b x] on the attitude error, 1 on the drift
/// (the clock states of the satellite's receiver, and its clock estimates passed in).
/// The attitude columns follow
/// from C_b_n,est = (I - [phi x]) C_b_n, as in the loosely coupled rows
/// (aiding_measurements.hpp). The rate's dependence on position through l is neglected, as in
/// seed 000 eq. 5, and so is the gyro-bias error's share of the antenna velocity.
RangePrediction predictRange(const NavState& ins, double clock_bias_m, double clock_drift_mps,
                             const SatelliteObservation& sat, const AntennaArm& antenna = {});

}  // namespace navbus::core
