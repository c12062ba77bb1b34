// The statistic of one group of GLR directions at one onset (seed 000 eqs. 11-12): the
// magnitude nu = R^+ f and l = 1/2 f^T R^+ f with the number of identifiable directions, for
// the window's sums f and R (glr_window.hpp). R is ill-conditioned when two directions have
// (nearly) the same signature (a pseudorange step and ramp one epoch after onset; x-accelerometer
// and y-gyro in straight flight): the fit scales R to unit diagonal and drops the directions
// whose information is within a tolerance of dependent (doc/glr_closed_loop.md).
#pragma once

#include <Eigen/Core>

namespace navbus::core::glr {

struct GroupFit {
  double statistic{0.0};  ///< 1/2 f^T R^+ f
  int rank{0};
};

/// l = 1/2 f^T R^+ f of one group of N directions (eq. 12) and rank(R), directions whose
/// unexplained share of information falls below `tolerance` dropped. Instantiated for the IMU
/// group (6) and a satellite's (3).
template <int N>
GroupFit fitGroup(const Eigen::Matrix<double, N, N>& R, const Eigen::Matrix<double, N, 1>& f,
                  double tolerance);

/// fitGroup<3>(R, f, tolerance).statistic, in closed form when R is provably full rank.
double satelliteGroupStatistic(const Eigen::Matrix3d& R, const Eigen::Vector3d& f,
                               double tolerance);

}  // namespace navbus::core::glr
