// Loosely coupled aiding measurements over the 17-state layout: GNSS position and velocity
// (seed 004 eq. 5, seed 001) and star-tracker attitude (seed 001 eq. 17). Each returns the
// innovation z = predicted - measured in error-state form (z = H dx + v), H and R.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navbus/core/state_layout.hpp"
#include "navbus/core/strapdown.hpp"

namespace navbus::core {

struct VectorMeasurement {
  Eigen::Vector3d z;                        ///< innovation, predicted minus measured
  Eigen::Matrix<double, 3, tc17::kSize> h;  ///< d z / d dx
  Eigen::Matrix3d r;                        ///< measurement noise covariance
};

/// GNSS position fix: z = (INS position - fix position) in NED metres (lever arm zero).
VectorMeasurement positionMeasurement(const NavState& ins, const earth::Geodetic& fix,
                                      const Eigen::Vector3d& sigma_ned_m);

/// GNSS velocity: z = INS velocity - fix velocity [m/s, NED].
VectorMeasurement velocityMeasurement(const NavState& ins, const Eigen::Vector3d& fix_vel_ned_mps,
                                      const Eigen::Vector3d& sigma_ned_mps);

/// Star tracker: the measured body-to-ECI attitude brought into NED at the INS position and
/// time; z = phi_INS - phi_ST (seed 001 eq. 17) as the small rotation between the INS attitude
/// and the measured one, so that H selects phi. Body-axis sigmas are rotated into NED.
VectorMeasurement attitudeMeasurement(const NavState& ins,
                                      const Eigen::Quaterniond& q_b_to_i_measured,
                                      const Eigen::Vector3d& sigma_b_rad);

}  // namespace navbus::core
