// How the IMU sits in the vehicle: the rotation of its sensor axes against the body axes
// (forward, right, down), applied to every increment before the strapdown sees it.
#pragma once

#include <Eigen/Core>

#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/math/rotation.hpp"

namespace navbus::core {

struct ImuMounting {
  /// Takes sensor-axis vectors into body axes: v_b = C v_s.
  Eigen::Matrix3d sensor_to_body{Eigen::Matrix3d::Identity()};

  /// From the sensor's roll, pitch and yaw [rad] as RTKLIB-style "IMU to body" angles give them:
  /// Rz(yaw) Ry(pitch) Rx(roll) takes body vectors into sensor axes (docs/real_data.md shows
  /// the check on the drive's standing start), so the sensor-to-body rotation is its transpose.
  static ImuMounting fromRollPitchYaw(const Eigen::Vector3d& roll_pitch_yaw_rad) {
    return {dcmFromEuler(roll_pitch_yaw_rad).transpose()};
  }

  ImuIncrement toBody(ImuIncrement inc) const {
    inc.delta_vel_b_mps = sensor_to_body * inc.delta_vel_b_mps;
    inc.delta_angle_b_rad = sensor_to_body * inc.delta_angle_b_rad;
    return inc;
  }
};

}  // namespace navbus::core
