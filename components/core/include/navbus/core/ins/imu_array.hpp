// An array of redundant IMUs, as the parity test (integrity/imu_array_parity.hpp) and the
// least-squares combination (ins/imu_array_combination.hpp) see it: each unit's mounting and
// place, its noise per sample. Unit i's gyro axis a senses e_a^T C_u_b dtheta_b; its
// accelerometer axis a senses e_a^T C_u_b (dv_b + (dw/dt x r_u + w x (w x r_u)) dt): a rigid
// body, r_u the unit's place from the body origin.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace navbus::core {

/// One IMU of the array.
struct ImuArrayUnit {
  Eigen::Matrix3d c_u_b{Eigen::Matrix3d::Identity()};      ///< body -> unit axes
  Eigen::Vector3d lever_arm_b_m{Eigen::Vector3d::Zero()};  ///< place from the body origin
  double gyro_sigma_rad{0.0};   ///< white noise of one angle increment (ARW sqrt(dt)) [rad]
  double accel_sigma_mps{0.0};  ///< white noise of one velocity increment (VRW sqrt(dt)) [m/s]
};

enum class ImuInstrument { kGyro = 0, kAccelerometer = 1 };
inline constexpr int kImuInstrumentKinds = 2;

/// The specific force a unit at r_b senses beyond the body origin's on a rigid body turning at
/// w_b with dw_b/dt [m/s^2, body]: dw/dt x r + w x (w x r).
inline Eigen::Vector3d leverArmSpecificForce(const Eigen::Vector3d& w_b_radps,
                                             const Eigen::Vector3d& w_dot_b_radps2,
                                             const Eigen::Vector3d& r_b_m) {
  return w_dot_b_radps2.cross(r_b_m) + w_b_radps.cross(w_b_radps.cross(r_b_m));
}

/// false with `error` naming the unit and the field when the array cannot be used: fewer than
/// 2 or more than max_units units, a mounting that is not a rotation, a lever arm that is not
/// finite, a sigma that is not positive, an interval that is not positive.
bool checkImuArray(const std::vector<ImuArrayUnit>& units, double interval_s, int max_units,
                   std::string& error);

}  // namespace navbus::core
