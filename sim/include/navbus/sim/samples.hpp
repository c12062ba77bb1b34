// Simulated sensor outputs in SI units (no DDS types; the sensor_sim participant converts).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/math/earth.hpp"

namespace navbus::sim {

struct RawImuSample {
  Eigen::Vector3d angular_rate_b_radps{Eigen::Vector3d::Zero()};
  Eigen::Vector3d specific_force_b_mps2{Eigen::Vector3d::Zero()};
};

/// Raw samples of one navigation interval, the i-th at first_time_ns + round(i * period).
struct RawImuBlock {
  std::int64_t first_time_ns{0};
  double sample_period_s{0.0};
  std::vector<RawImuSample> samples;
};

struct SatelliteMeasurement {
  int sv_id{0};
  double pseudorange_m{0.0};
  double pseudorange_rate_mps{0.0};
  Eigen::Vector3d sat_pos_ecef_m{Eigen::Vector3d::Zero()};  ///< at transmission, ECEF at reception
  Eigen::Vector3d sat_vel_ecef_mps{Eigen::Vector3d::Zero()};
  double sat_clock_correction_m{0.0};
  double sat_clock_drift_mps{0.0};
  double cn0_dbhz{0.0};
  double pseudorange_sigma_m{0.0};
  double pseudorange_rate_sigma_mps{0.0};
  double elevation_rad{0.0};
};

struct GnssEpoch {
  std::int64_t time_ns{0};  ///< reception time
  std::vector<SatelliteMeasurement> satellites;
};

struct GnssFixSample {
  std::int64_t time_ns{0};
  core::earth::Geodetic position;
  Eigen::Vector3d vel_ned_mps{Eigen::Vector3d::Zero()};
  Eigen::Vector3d pos_sigma_ned_m{Eigen::Vector3d::Zero()};
  Eigen::Vector3d vel_sigma_ned_mps{Eigen::Vector3d::Zero()};
  int num_satellites{0};
  bool valid{false};
  double pdop{0.0};  ///< 0 when the fix does not come from the pseudoranges
};

struct StarTrackerSample {
  std::int64_t time_ns{0};
  Eigen::Quaterniond q_b_to_i{Eigen::Quaterniond::Identity()};
  Eigen::Vector3d sigma_b_rad{Eigen::Vector3d::Zero()};
};

/// One further IMU unit's increment over the interval (ScenarioConfig::extra_imus).
struct UnitImuIncrement {
  core::ImuIncrement increment;  ///< in the unit's own axes
  /// The unit's total biases at the end of the interval, model + injected faults [unit axes]
  Eigen::Vector3d truth_accel_bias_u_mps2{Eigen::Vector3d::Zero()};
  Eigen::Vector3d truth_gyro_bias_u_radps{Eigen::Vector3d::Zero()};
};

/// Everything the source produces for one navigation interval ending at `time_ns`.
struct SensorFrame {
  std::int64_t time_ns{0};
  core::ImuIncrement increment;
  RawImuBlock raw;
  /// The further IMU units, in ScenarioConfig::extra_imus order (unit k + 1 at index k).
  std::vector<UnitImuIncrement> extra_imus;
  bool has_gnss{false};  ///< the scenario's receiver has an epoch (and a fix) at this time
  GnssEpoch gnss;
  GnssFixSample fix;
  /// The further receivers' epochs at the scenario receiver's epoch times
  /// (ScenarioConfig::extra_receivers order), with those of a receiver out marked silent.
  std::vector<GnssEpoch> extra_gnss;
  std::vector<bool> extra_gnss_silent;  ///< per further receiver: out at this time
  /// The further receivers' epochs hold this time (whatever the scenario's receiver does).
  bool has_extra_gnss{false};
  bool has_star_tracker{false};
  StarTrackerSample star_tracker;
  core::NavState truth;
  Eigen::Vector3d truth_accel_bias_b_mps2{Eigen::Vector3d::Zero()};  ///< model + injected faults
  Eigen::Vector3d truth_gyro_bias_b_radps{Eigen::Vector3d::Zero()};
  /// The star tracker's bias at its latest sample [rad, tracker axes]: model + injected faults.
  Eigen::Vector3d truth_star_tracker_bias_b_rad{Eigen::Vector3d::Zero()};
};

}  // namespace navbus::sim
