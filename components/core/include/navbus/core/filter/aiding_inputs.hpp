// Aiding inputs in SI as the core takes them: a GNSS position/velocity fix and a star-tracker
// attitude (the engine fuses them, the initial alignment starts from them).
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navbus/core/math/earth.hpp"

namespace navbus::core {

/// A GNSS receiver's position/velocity solution.
struct GnssFixMeasurement {
  std::int64_t time_ns{0};                                     ///< GPS time of validity
  earth::Geodetic position;                                    ///< WGS84 (antenna)
  Eigen::Vector3d vel_ned_mps{Eigen::Vector3d::Zero()};        ///< w.r.t. Earth, NED
  Eigen::Vector3d pos_sigma_ned_m{Eigen::Vector3d::Ones()};    ///< 1 sigma per NED axis
  Eigen::Vector3d vel_sigma_ned_mps{Eigen::Vector3d::Ones()};  ///< 1 sigma per NED axis
  /// The velocity is valid at time_ns plus this [ns]: negative for a receiver whose velocity
  /// lags its position (the engine brings it to the state's time, ins/velocity_history.hpp).
  std::int64_t velocity_time_offset_ns{0};
};

/// A star tracker's attitude, already rotated into the IMU body frame.
struct StarAttitudeMeasurement {
  std::int64_t time_ns{0};                                      ///< GPS time of validity
  Eigen::Quaterniond q_b_to_i{Eigen::Quaterniond::Identity()};  ///< body -> ECI
  Eigen::Vector3d sigma_b_rad{Eigen::Vector3d::Ones()};         ///< 1 sigma about each body axis
};

}  // namespace navbus::core
