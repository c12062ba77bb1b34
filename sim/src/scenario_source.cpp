#include "navbus/sim/scenario_source.hpp"

#include <cmath>

#include "navbus/core/math/rotation.hpp"

namespace navbus::sim {

namespace earth = core::earth;

namespace {
std::unique_ptr<Trajectory> makeTrajectory(const ScenarioConfig& c) {
  if (c.orbit) {
    OrbitStart o = c.orbit_start;
    o.start_gps_s = 1e-9 * static_cast<double>(c.start_time_ns);
    return std::make_unique<CircularOrbitTrajectory>(o);
  }
  return std::make_unique<VehicleTrajectory>(c.vehicle, c.segments, c.gravity);
}
}  // namespace

ScenarioSource::ScenarioSource(const ScenarioConfig& c)
    : config_(c),
      trajectory_(makeTrajectory(c)),
      // Independent random streams per model, all derived from the one scenario seed.
      imu_(c.imu, c.seed * 4 + 1),
      dither_([&] {
        DitherSpec d = c.dither_spec;
        d.seed = c.seed * 4 + 2;
        return d;
      }()),
      vibration_(c.vibration,
                 1e9 * c.raw_samples_per_increment / static_cast<double>(c.imu_period_ns),
                 c.seed * 4 + 5),
      constellation_(c.constellation),
      receiver_(c.gnss, constellation_),
      star_(c.star_tracker, c.seed * 4 + 3),
      rng_(c.seed * 4) {}

Eigen::Vector3d ScenarioSource::frozen(SensorKind sensor, const Eigen::Vector3d& rate, double t) {
  Eigen::Vector3d out = rate;
  Eigen::Vector3d& stuck = sensor == SensorKind::kAccelerometer ? stuck_accel_ : stuck_gyro_;
  const Eigen::Vector3d& last = sensor == SensorKind::kAccelerometer ? last_accel_ : last_gyro_;
  for (int i = 0; i < 3; ++i) {
    if (config_.faults.stuckSince(sensor, i, t)) {
      if (std::isnan(stuck[i])) stuck[i] = last[i];  // frozen at the last output before onset
      out[i] = stuck[i];
    } else {
      stuck[i] = std::nan("");
    }
  }
  return out;
}

namespace {
/// A default frame that keeps the capacity of its raw-sample buffer (one per IMU frame; a GNSS
/// epoch's satellites come as a new vector from the receiver model, 10 Hz at most).
void clearKeepingRawBuffer(SensorFrame& f) {
  std::vector<RawImuSample> raw = std::move(f.raw.samples);
  f = SensorFrame{};
  raw.clear();
  f.raw.samples = std::move(raw);
}
}  // namespace

SensorFrame ScenarioSource::next() {
  SensorFrame f;
  next(f);
  return f;
}

void ScenarioSource::next(SensorFrame& f) {
  ++index_;
  clearKeepingRawBuffer(f);
  const std::int64_t t_end = config_.start_time_ns + index_ * config_.imu_period_ns;
  const std::int64_t t_begin = t_end - config_.imu_period_ns;
  f.time_ns = t_end;
  const int n = config_.raw_samples_per_increment;
  const double T = 1e-9 * static_cast<double>(config_.imu_period_ns);
  const double dt = T / n;
  const double t0 = 1e-9 * static_cast<double>(t_begin - config_.start_time_ns);

  f.raw.first_time_ns = t_begin + std::llround(1e9 * dt);
  f.raw.sample_period_s = dt;
  f.raw.samples.resize(static_cast<std::size_t>(n));
  f.increment.time_ns = t_end;
  f.increment.interval_s = T;
  for (int i = 0; i < n; ++i) {
    const double t = t0 + (i + 1) * dt;  // the raw sample is the mean over (t - dt, t]
    const PerfectIncrement perfect = trajectory_->advance(dt);
    PerfectIncrement sensed = imu_.apply(perfect, trajectory_->specificForceBody(), dt);
    sensed.delta_vel_b_mps += config_.faults.accelBias(t) * dt;
    sensed.delta_angle_b_rad += config_.faults.gyroBias(t) * dt;
    if (config_.vibration.enabled) {
      const auto [f_vib, w_vib] =
          vibration_.next(trajectory_->state().vel_ned_mps.head<2>().norm());
      sensed.delta_vel_b_mps += f_vib * dt;
      sensed.delta_angle_b_rad += w_vib * dt;
    }
    // Mean rates over the sample; a stuck axis outputs its frozen value (no dither either:
    // the loss of the dither is how seed 003 detects it).
    const Eigen::Vector3d accel =
        frozen(SensorKind::kAccelerometer, sensed.delta_vel_b_mps / dt, t);
    const Eigen::Vector3d gyro = frozen(SensorKind::kGyro, sensed.delta_angle_b_rad / dt, t);
    last_accel_ = accel;
    last_gyro_ = gyro;
    auto& raw = f.raw.samples[static_cast<std::size_t>(i)];
    raw.specific_force_b_mps2 = accel;
    raw.angular_rate_b_radps = gyro;
    if (config_.dither) {
      const DitherSample d = dither_.at(t);
      for (int a = 0; a < 3; ++a) {
        if (!config_.faults.stuckSince(SensorKind::kAccelerometer, a, t))
          raw.specific_force_b_mps2[a] += d.specific_force_b_mps2[a];
        if (!config_.faults.stuckSince(SensorKind::kGyro, a, t))
          raw.angular_rate_b_radps[a] += d.angular_rate_b_radps[a];
      }
    }
    // The navigation-rate increments are the dither-stripped sums of the raw stream.
    f.increment.delta_vel_b_mps += accel * dt;
    f.increment.delta_angle_b_rad += gyro * dt;
  }
  f.truth = trajectory_->state();
  f.truth.time_ns = t_end;
  f.truth_accel_bias_b_mps2 = imu_.accelBias() + config_.faults.accelBias(t0 + T);
  f.truth_gyro_bias_b_radps = imu_.gyroBias() + config_.faults.gyroBias(t0 + T);

  const double t_s = t0 + T;
  if (config_.gnss_every_n_increments > 0 && index_ % config_.gnss_every_n_increments == 0 &&
      !config_.faults.gnssOut(t_s)) {
    f.has_gnss = true;
    const Eigen::Vector3d r_e = earth::geodeticToEcef(f.truth.position);
    const Eigen::Matrix3d C_n_e =
        earth::C_n_e(f.truth.position.latitude_rad, f.truth.position.longitude_rad);
    f.gnss =
        receiver_.observe(t_end, config_.start_time_ns, r_e, C_n_e * f.truth.vel_ned_mps, rng_);
    for (auto& s : f.gnss.satellites)
      s.pseudorange_m += config_.faults.pseudorangeError(s.sv_id, t_s);
    f.fix = receiver_.fix(f.gnss, f.truth.position, f.truth.vel_ned_mps, rng_);
    const Eigen::Vector3d pulse = config_.faults.positionPulse(t_s);
    if (pulse.squaredNorm() > 0.0) f.fix.position = earth::offsetNed(f.fix.position, pulse);
  }
  if (config_.star_tracker_every_n_increments > 0 &&
      index_ % config_.star_tracker_every_n_increments == 0) {
    const Eigen::Matrix3d C_e_i = earth::C_i_e(1e-9 * static_cast<double>(t_end)).transpose();
    const Eigen::Matrix3d C_n_e =
        earth::C_n_e(f.truth.position.latitude_rad, f.truth.position.longitude_rad);
    const Eigen::Quaterniond q_true(C_e_i * C_n_e * f.truth.q_b_to_n.toRotationMatrix());
    const double dt_st = T * config_.star_tracker_every_n_increments;
    const auto q = star_.measure(q_true, dt_st);
    star_bias_b_rad_ = star_.bias() + config_.faults.starTrackerBias(t_s);
    if (q && !config_.faults.starTrackerOut(t_s)) {
      f.has_star_tracker = true;
      f.star_tracker.time_ns = t_end;
      f.star_tracker.q_b_to_i =
          (*q * core::quaternionFromRotationVector(config_.faults.starTrackerBias(t_s)))
              .normalized();
      f.star_tracker.sigma_b_rad.setConstant(
          std::hypot(config_.star_tracker.noise_rad, config_.star_tracker.bias_rad));
    }
  }
  f.truth_star_tracker_bias_b_rad = star_bias_b_rad_;
}

}  // namespace navbus::sim
