#include "navbus/sim/scenario_source.hpp"

#include <cmath>
#include <tuple>

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
      rng_(c.seed * 4),
      fault_rng_(c.seed * 4 + 6) {
  // Each further unit's noise from a stream of its own (a step of the golden-ratio constant
  // apart from the others'), derived from the one scenario seed.
  for (std::size_t k = 0; k < c.extra_imus.size(); ++k)
    extra_.push_back(
        {ImuErrorModel(c.extra_imus[k].imu, c.seed * 4 + 1 + 0x9E3779B97F4A7C15ull * (k + 1)),
         {},
         Eigen::Vector3d::Constant(std::nan(""))});
  // Each further receiver: the scenario's receiver model with its own clock, its own noise.
  extra_receivers_.reserve(c.extra_receivers.size());
  for (std::size_t k = 0; k < c.extra_receivers.size(); ++k) {
    GnssReceiverConfig g = c.gnss;
    g.clock_bias_m = c.extra_receivers[k].clock_bias_m;
    g.clock_drift_mps = c.extra_receivers[k].clock_drift_mps;
    extra_receivers_.push_back({GnssReceiverModel(g, constellation_),
                                std::mt19937_64(c.seed * 4 + 0x9E3779B97F4A7C15ull * (k + 1))});
  }
}

void ScenarioSource::observeExtraReceivers(std::int64_t t_ns, const Eigen::Vector3d& r_e,
                                           const Eigen::Matrix3d& C_n_e, double t_s,
                                           SensorFrame& f) {
  const Eigen::Matrix3d C_b_e = C_n_e * f.truth.q_b_to_n.toRotationMatrix();
  const Eigen::Vector3d v_e = C_n_e * f.truth.vel_ned_mps;  // the body's (w x r left out)
  f.extra_gnss.resize(extra_receivers_.size());
  f.extra_gnss_silent.assign(extra_receivers_.size(), false);
  f.has_extra_gnss = !extra_receivers_.empty();
  for (std::size_t k = 0; k < extra_receivers_.size(); ++k) {
    f.extra_gnss_silent[k] = config_.faults.receiverOut(t_s, static_cast<int>(k) + 1);
    ExtraReceiver& rx = extra_receivers_[k];
    const Eigen::Vector3d antenna_e = r_e + C_b_e * config_.extra_receivers[k].antenna_b_m;
    f.extra_gnss[k] = rx.model.observe(t_ns, config_.start_time_ns, antenna_e, v_e, rx.rng);
    for (auto& sat : f.extra_gnss[k].satellites)
      sat.pseudorange_m += config_.faults.pseudorangeError(sat.sv_id, t_s, static_cast<int>(k) + 1);
  }
}

Eigen::Vector3d ScenarioSource::frozen(UnitOutputs& unit, int unit_index, SensorKind sensor,
                                       const Eigen::Vector3d& rate, double t) {
  Eigen::Vector3d out = rate;
  const bool accel = sensor == SensorKind::kAccelerometer;
  Eigen::Vector3d& stuck = accel ? unit.stuck_accel : unit.stuck_gyro;
  const Eigen::Vector3d& last = accel ? unit.last_accel : unit.last_gyro;
  for (int i = 0; i < 3; ++i) {
    if (config_.faults.stuckSince(sensor, i, t, unit_index)) {
      if (std::isnan(stuck[i])) stuck[i] = last[i];  // frozen at the last output before onset
      out[i] = stuck[i];
    } else {
      stuck[i] = std::nan("");
    }
  }
  (accel ? unit.last_accel : unit.last_gyro) = out;
  return out;
}

void ScenarioSource::applyAxisFaults(const PerfectIncrement& input, const ImuSpec& spec, int unit,
                                     double t, double dt, PerfectIncrement& sensed) {
  const FaultSchedule& faults = config_.faults;
  sensed.delta_vel_b_mps +=
      faults.scaleError(t, SensorKind::kAccelerometer, unit).cwiseProduct(input.delta_vel_b_mps);
  sensed.delta_angle_b_rad +=
      faults.scaleError(t, SensorKind::kGyro, unit).cwiseProduct(input.delta_angle_b_rad);
  // White noise of density k N: the specified N's share is in `sensed`, the rest added here
  // (an increment's white noise over dt has sigma N sqrt(dt)).
  std::normal_distribution<double> unit_normal(0.0, 1.0);
  const auto addNoise = [&](SensorKind sensor, double density, Eigen::Vector3d& delta) {
    const Eigen::Vector3d k = faults.noiseFactor(t, sensor, unit);
    for (int a = 0; a < 3; ++a) {
      if (k[a] <= 1.0) continue;
      delta[a] += density * std::sqrt((k[a] * k[a] - 1.0) * dt) * unit_normal(fault_rng_);
    }
  };
  addNoise(SensorKind::kAccelerometer, spec.accel.random_walk, sensed.delta_vel_b_mps);
  addNoise(SensorKind::kGyro, spec.gyro.random_walk, sensed.delta_angle_b_rad);
}

void ScenarioSource::senseExtraUnit(int k, const PerfectIncrement& perfect,
                                    const Eigen::Vector3d& f_b,
                                    const Eigen::Vector3d& vibration_f_b,
                                    const Eigen::Vector3d& vibration_w_b, double t, double dt,
                                    SensorFrame& f) {
  ExtraUnit& u = extra_[static_cast<std::size_t>(k)];
  const ImuUnit& spec = config_.extra_imus[static_cast<std::size_t>(k)];
  const int unit = k + 1;
  // A rigid body: at the lever arm r the specific force gains dw/dt x r + w x (w x r), with w the
  // sample's mean rate and dw/dt from the previous sample's (first order over the sample). The
  // units share the mount's vibration: its rate is part of w (the vehicle's rotation plus the
  // mount's oscillation), so a unit off the reference sees the oscillation's tangential and
  // centripetal specific force too (an oscillation at 20 Hz of 0.3 deg/s RMS gives about
  // 0.66 rad/s^2 RMS, 27 mg at 0.4 m).
  const Eigen::Vector3d w = perfect.delta_angle_b_rad / dt + vibration_w_b;
  const Eigen::Vector3d w_dot = std::isnan(u.previous_rate_b.x())
                                    ? Eigen::Vector3d::Zero()
                                    : Eigen::Vector3d((w - u.previous_rate_b) / dt);
  u.previous_rate_b = w;
  const Eigen::Vector3d& r = spec.lever_arm_b_m;
  const Eigen::Vector3d arm_f = w_dot.cross(r) + w.cross(w.cross(r));
  PerfectIncrement at_unit;
  at_unit.delta_angle_b_rad = spec.c_u_b * perfect.delta_angle_b_rad;
  at_unit.delta_vel_b_mps = spec.c_u_b * (perfect.delta_vel_b_mps + arm_f * dt);
  PerfectIncrement sensed = u.model.apply(at_unit, spec.c_u_b * (f_b + arm_f), dt);
  applyAxisFaults(at_unit, spec.imu, unit, t, dt, sensed);
  sensed.delta_vel_b_mps += config_.faults.accelBias(t, unit) * dt;
  sensed.delta_angle_b_rad += config_.faults.gyroBias(t, unit) * dt;
  sensed.delta_vel_b_mps += spec.c_u_b * vibration_f_b * dt;
  sensed.delta_angle_b_rad += spec.c_u_b * vibration_w_b * dt;
  const Eigen::Vector3d accel =
      frozen(u.outputs, unit, SensorKind::kAccelerometer, sensed.delta_vel_b_mps / dt, t);
  const Eigen::Vector3d gyro =
      frozen(u.outputs, unit, SensorKind::kGyro, sensed.delta_angle_b_rad / dt, t);
  core::ImuIncrement& inc = f.extra_imus[static_cast<std::size_t>(k)].increment;
  inc.delta_vel_b_mps += accel * dt;
  inc.delta_angle_b_rad += gyro * dt;
}

namespace {
/// A default frame that keeps the capacity of its raw-sample and unit buffers (one per IMU
/// frame; a GNSS epoch's satellites come as a new vector from the receiver model, 10 Hz at most).
void clearKeepingBuffers(SensorFrame& f) {
  std::vector<RawImuSample> raw = std::move(f.raw.samples);
  std::vector<UnitImuIncrement> units = std::move(f.extra_imus);
  std::vector<GnssEpoch> receivers = std::move(f.extra_gnss);
  f = SensorFrame{};
  raw.clear();
  units.clear();
  receivers.clear();
  f.raw.samples = std::move(raw);
  f.extra_imus = std::move(units);
  f.extra_gnss = std::move(receivers);
}
}  // namespace

SensorFrame ScenarioSource::next() {
  SensorFrame f;
  next(f);
  return f;
}

void ScenarioSource::next(SensorFrame& f) {
  ++index_;
  clearKeepingBuffers(f);
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
  f.extra_imus.resize(extra_.size());
  for (UnitImuIncrement& u : f.extra_imus) {
    u.increment.time_ns = t_end;
    u.increment.interval_s = T;
  }
  for (int i = 0; i < n; ++i) {
    const double t = t0 + (i + 1) * dt;  // the raw sample is the mean over (t - dt, t]
    const PerfectIncrement perfect = trajectory_->advance(dt);
    const Eigen::Vector3d f_b = trajectory_->specificForceBody();
    PerfectIncrement sensed = imu_.apply(perfect, f_b, dt);
    applyAxisFaults(perfect, config_.imu, 0, t, dt, sensed);
    sensed.delta_vel_b_mps += config_.faults.accelBias(t) * dt;
    sensed.delta_angle_b_rad += config_.faults.gyroBias(t) * dt;
    Eigen::Vector3d f_vib = Eigen::Vector3d::Zero(), w_vib = Eigen::Vector3d::Zero();
    if (config_.vibration.enabled) {
      std::tie(f_vib, w_vib) = vibration_.next(trajectory_->state().vel_ned_mps.head<2>().norm());
      sensed.delta_vel_b_mps += f_vib * dt;
      sensed.delta_angle_b_rad += w_vib * dt;
    }
    for (int k = 0; k < static_cast<int>(extra_.size()); ++k)
      senseExtraUnit(k, perfect, f_b, f_vib, w_vib, t, dt, f);
    // Mean rates over the sample; a stuck axis outputs its frozen value (no dither either:
    // the loss of the dither is how seed 003 detects it).
    const Eigen::Vector3d accel =
        frozen(outputs_, 0, SensorKind::kAccelerometer, sensed.delta_vel_b_mps / dt, t);
    const Eigen::Vector3d gyro =
        frozen(outputs_, 0, SensorKind::kGyro, sensed.delta_angle_b_rad / dt, t);
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
  for (std::size_t k = 0; k < extra_.size(); ++k) {
    const int unit = static_cast<int>(k) + 1;
    f.extra_imus[k].truth_accel_bias_u_mps2 =
        extra_[k].model.accelBias() + config_.faults.accelBias(t0 + T, unit);
    f.extra_imus[k].truth_gyro_bias_u_radps =
        extra_[k].model.gyroBias() + config_.faults.gyroBias(t0 + T, unit);
  }

  const double t_s = t0 + T;
  if (config_.gnss_every_n_increments > 0 && index_ % config_.gnss_every_n_increments == 0 &&
      !config_.faults.gnssOut(t_s)) {
    // A receiver out on its own is observed all the same (its noise sequence goes on), and its
    // epoch left unsent.
    f.has_gnss = !config_.faults.receiverOut(t_s, 0);
    const Eigen::Vector3d r_e = earth::geodeticToEcef(f.truth.position);
    const Eigen::Matrix3d C_n_e =
        earth::C_n_e(f.truth.position.latitude_rad, f.truth.position.longitude_rad);
    f.gnss =
        receiver_.observe(t_end, config_.start_time_ns, r_e, C_n_e * f.truth.vel_ned_mps, rng_);
    for (auto& s : f.gnss.satellites)
      s.pseudorange_m += config_.faults.pseudorangeError(s.sv_id, t_s);
    f.fix = receiver_.fix(f.gnss, f.truth.position, f.truth.vel_ned_mps, rng_);
    observeExtraReceivers(t_end, r_e, C_n_e, t_s, f);
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
