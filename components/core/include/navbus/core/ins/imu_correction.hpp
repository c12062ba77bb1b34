// The IMU's estimated output errors and their removal from an increment. Per axis, a sensor
// reads (1 + s) times the true specific force or rate plus its bias b, so the truth is
// (reading - b) / (1 + s); the filter estimates b and s (state_layout.hpp).
#pragma once

#include <Eigen/Core>

#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

struct ImuCorrection {
  Eigen::Vector3d accel_bias_b_mps2{Eigen::Vector3d::Zero()};
  Eigen::Vector3d gyro_bias_b_radps{Eigen::Vector3d::Zero()};
  Eigen::Vector3d accel_scale_b{Eigen::Vector3d::Zero()};  ///< scale-factor error [1]
  Eigen::Vector3d gyro_scale_b{Eigen::Vector3d::Zero()};   ///< scale-factor error [1]

  ImuIncrement applied(ImuIncrement inc) const {
    inc.delta_vel_b_mps = (inc.delta_vel_b_mps - accel_bias_b_mps2 * inc.interval_s)
                              .cwiseQuotient(Eigen::Vector3d::Ones() + accel_scale_b);
    inc.delta_angle_b_rad = (inc.delta_angle_b_rad - gyro_bias_b_radps * inc.interval_s)
                                .cwiseQuotient(Eigen::Vector3d::Ones() + gyro_scale_b);
    return inc;
  }
};

}  // namespace navbus::core
