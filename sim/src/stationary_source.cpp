#include "navbus/sim/stationary_source.hpp"

#include <cmath>

#include "navbus/core/rotation.hpp"

namespace navbus::sim {

namespace earth = core::earth;

StationarySource::StationarySource(const StationarySourceConfig& config)
    : config_(config),
      constellation_(config.constellation),
      receiver_(config.gnss, constellation_),
      rng_(config.seed) {
  const Eigen::Matrix3d C_b_n = core::dcmFromEuler(config.roll_pitch_yaw_rad);
  const Eigen::Matrix3d C_n_b = C_b_n.transpose();
  // At rest in ECEF: the specific force balances normal gravity (gravitation + centrifugal),
  // and the body turns with the Earth.
  ideal_.specific_force_b_mps2 =
      -(C_n_b * earth::gravityNed(config.position.latitude_rad, config.position.height_m));
  ideal_.angular_rate_b_radps = C_n_b * earth::omegaIeNed(config.position.latitude_rad);
  truth_.time_ns = config.start_time_ns;
  truth_.position = config.position;
  truth_.vel_ned_mps.setZero();
  truth_.q_b_to_n = Eigen::Quaterniond(C_b_n);
  pos_ecef_m_ = earth::geodeticToEcef(config.position);
}

SensorFrame StationarySource::next() {
  ++index_;
  std::normal_distribution<double> unit(0.0, 1.0);
  SensorFrame f;
  const std::int64_t t_end = config_.start_time_ns + index_ * config_.imu_period_ns;
  const std::int64_t t_begin = t_end - config_.imu_period_ns;
  f.time_ns = t_end;

  // Raw samples: each is the mean over its sub-interval, so their sum times the sample period
  // is exactly the navigation-rate increment (the two streams are consistent by construction).
  const int n = config_.raw_samples_per_increment;
  const double dt_raw = 1e-9 * static_cast<double>(config_.imu_period_ns) / n;
  const double accel_sigma = config_.imu.accel_noise_density_mps2_per_sqrthz / std::sqrt(dt_raw);
  const double gyro_sigma = config_.imu.gyro_noise_density_radps_per_sqrthz / std::sqrt(dt_raw);
  f.raw.first_time_ns = t_begin + static_cast<std::int64_t>(std::llround(1e9 * dt_raw));
  f.raw.sample_period_s = dt_raw;
  f.raw.samples.resize(static_cast<std::size_t>(n));
  f.increment.time_ns = t_end;
  f.increment.interval_s = 1e-9 * static_cast<double>(config_.imu_period_ns);
  for (auto& s : f.raw.samples) {
    for (int i = 0; i < 3; ++i) {
      s.specific_force_b_mps2[i] = ideal_.specific_force_b_mps2[i] +
                                   config_.imu.accel_bias_b_mps2[i] + accel_sigma * unit(rng_);
      s.angular_rate_b_radps[i] = ideal_.angular_rate_b_radps[i] +
                                  config_.imu.gyro_bias_b_radps[i] + gyro_sigma * unit(rng_);
    }
    f.increment.delta_vel_b_mps += s.specific_force_b_mps2 * dt_raw;
    f.increment.delta_angle_b_rad += s.angular_rate_b_radps * dt_raw;
  }

  truth_.time_ns = t_end;
  f.truth = truth_;

  if (config_.gnss_every_n_increments > 0 && index_ % config_.gnss_every_n_increments == 0) {
    f.has_gnss = true;
    f.gnss =
        receiver_.observe(t_end, config_.start_time_ns, pos_ecef_m_, Eigen::Vector3d::Zero(), rng_);
    f.fix = receiver_.fix(f.gnss, truth_.position, truth_.vel_ned_mps, rng_);
  }
  if (config_.star_tracker_every_n_increments > 0 &&
      index_ % config_.star_tracker_every_n_increments == 0) {
    f.has_star_tracker = true;
    const double t_s = 1e-9 * static_cast<double>(t_end);
    const Eigen::Matrix3d C_e_i = earth::C_i_e(t_s).transpose();
    const Eigen::Matrix3d C_n_e =
        earth::C_n_e(truth_.position.latitude_rad, truth_.position.longitude_rad);
    const Eigen::Quaterniond q_true(C_e_i * C_n_e * truth_.q_b_to_n.toRotationMatrix());
    const double s = config_.star_tracker_sigma_rad;
    const Eigen::Vector3d err(s * unit(rng_), s * unit(rng_), s * unit(rng_));
    f.star_tracker.time_ns = t_end;
    f.star_tracker.q_b_to_i = (q_true * core::quaternionFromRotationVector(err)).normalized();
    f.star_tracker.sigma_b_rad.setConstant(s);
  }
  return f;
}

}  // namespace navbus::sim
