// Single-epoch least-squares GNSS position/velocity/clock solution with dilution of precision.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace navbus::core {

/// One satellite's measurement, satellite clock already applied, Sagnac already applied to the
/// satellite position (positions expressed in the ECEF frame of reception time).
struct RangeObservation {
  Eigen::Vector3d sat_pos_ecef_m;
  Eigen::Vector3d sat_vel_ecef_mps;
  double pseudorange_m;
  double pseudorange_rate_mps;
};

struct LeastSquaresFix {
  bool valid{false};  ///< false: fewer than 4 satellites or no convergence
  Eigen::Vector3d pos_ecef_m{Eigen::Vector3d::Zero()};
  Eigen::Vector3d vel_ecef_mps{Eigen::Vector3d::Zero()};
  double clock_bias_m{0.0};     ///< c * receiver clock bias
  double clock_drift_mps{0.0};  ///< c * receiver clock drift
  double gdop{0.0}, pdop{0.0}, hdop{0.0}, vdop{0.0}, tdop{0.0};
  int iterations{0};
};

/// Gauss-Newton on the pseudoranges (position and clock), then linear least squares on the
/// rates (velocity and drift) with the same geometry. Equal weights.
LeastSquaresFix leastSquaresFix(
    const std::vector<RangeObservation>& obs,
    const Eigen::Vector3d& initial_pos_ecef_m = Eigen::Vector3d::Zero());

}  // namespace navbus::core
