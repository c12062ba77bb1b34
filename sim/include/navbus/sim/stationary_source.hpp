// A stationary vehicle on WGS84 with Earth rotation and normal gravity, seen by an IMU, a GNSS
// receiver and a star tracker. The physics is exact (the vehicle is at rest in ECEF, so specific
// force and inertial rate are constant in the body frame); the sensors add configured errors.
#pragma once

#include <cstdint>
#include <random>

#include "navbus/sim/constellation.hpp"
#include "navbus/sim/gnss_receiver.hpp"
#include "navbus/sim/samples.hpp"

namespace navbus::sim {

struct ImuErrorConfig {
  Eigen::Vector3d accel_bias_b_mps2{Eigen::Vector3d::Zero()};
  Eigen::Vector3d gyro_bias_b_radps{Eigen::Vector3d::Zero()};
  double accel_noise_density_mps2_per_sqrthz{0.0};  ///< velocity random walk
  double gyro_noise_density_radps_per_sqrthz{0.0};  ///< angle random walk
};

struct StationarySourceConfig {
  core::earth::Geodetic position;
  Eigen::Vector3d roll_pitch_yaw_rad{Eigen::Vector3d::Zero()};
  std::int64_t start_time_ns{0};  ///< GPS time of the start of the first interval
  std::int64_t imu_period_ns{10'000'000};
  int raw_samples_per_increment{24};
  int gnss_every_n_increments{100};
  int star_tracker_every_n_increments{20};
  ImuErrorConfig imu;
  double star_tracker_sigma_rad{0.3 / 3600.0 * M_PI / 180.0};
  GnssReceiverConfig gnss;
  ConstellationConfig constellation;
  std::uint64_t seed{1};
};

class StationarySource {
 public:
  explicit StationarySource(const StationarySourceConfig& config);

  /// Produces the next navigation interval.
  SensorFrame next();

  /// Ideal (error-free) specific force and inertial rate of the stationary body.
  const RawImuSample& idealImu() const { return ideal_; }
  std::int64_t index() const { return index_; }

 private:
  StationarySourceConfig config_;
  Constellation constellation_;
  GnssReceiverModel receiver_;
  std::mt19937_64 rng_;
  RawImuSample ideal_;
  core::NavState truth_;
  Eigen::Vector3d pos_ecef_m_;
  std::int64_t index_{0};
};

}  // namespace navbus::sim
