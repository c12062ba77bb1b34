#include "navbus/core/integrity/imu_array_parity.hpp"

#include <cmath>

#include <Eigen/Dense>

namespace navbus::core {

std::optional<ImuArrayParity> ImuArrayParity::make(const std::vector<ImuArrayUnit>& units,
                                                   double interval_s,
                                                   const ImuArrayParityConfig& config,
                                                   std::string& error) {
  if (!checkImuArray(units, interval_s, kMaxUnits, error)) return std::nullopt;
  if (config.reference_samples < 1 || !(config.reference_time_constant_samples >= 0.0)) {
    error = "IMU array: reference_samples " + std::to_string(config.reference_samples) +
            " must be >= 1 and the reference time constant " +
            std::to_string(config.reference_time_constant_samples) + " >= 0";
    return std::nullopt;
  }
  ImuArrayParity array(units, interval_s, config);
  for (int k = 0; k < kImuInstrumentKinds; ++k) {
    if (!array.build(static_cast<ImuInstrument>(k), error)) {
      error = std::string("IMU array, ") + (k == 0 ? "gyros" : "accelerometers") + ": " + error;
      return std::nullopt;
    }
  }
  return array;
}

ImuArrayParity::ImuArrayParity(std::vector<ImuArrayUnit> array_units, double interval_s,
                               const ImuArrayParityConfig& config)
    : units_(std::move(array_units)), interval_s_(interval_s), config_(config) {
  for (Channel& c : channels_) {
    c.rows = 3 * units();
    for (int i = 0; i < c.rows; ++i) c.instrument[static_cast<std::size_t>(i)] = i;
    c.reference = parity::Measurements::Zero(c.rows);
  }
}

bool ImuArrayParity::build(ImuInstrument kind, std::string& error) {
  Channel& c = channel(kind);
  parity::Axes axes(c.rows, 3);
  parity::Measurements sigmas(c.rows);
  for (int r = 0; r < c.rows; ++r) {
    const int i = c.instrument[static_cast<std::size_t>(r)];
    const ImuArrayUnit& unit = units_[static_cast<std::size_t>(i / 3)];
    axes.row(r) = unit.c_u_b.row(i % 3);  // eq. 1: the axis in body coordinates
    sigmas[r] = kind == ImuInstrument::kGyro
                    ? unit.gyro_sigma_rad
                    : accelerometerSigma(unit, unit.c_u_b.row(i % 3).transpose());
  }
  std::optional<ParitySpace> space = ParitySpace::make(axes, sigmas, error);
  c.glr.reset();
  if (!space) return false;
  c.glr = ParityGlr::make(*space, config_.glr, error);
  return c.glr.has_value();
}

double ImuArrayParity::accelerometerSigma(const ImuArrayUnit& unit,
                                          const Eigen::Vector3d& axis_b) const {
  // Eq. 1's lever-arm term is formed from dw/dt, the difference of two consecutive estimates of
  // the array's rate (fillAccelerometer), so the gyros' noise reaches every accelerometer off
  // the body origin: a . (dw/dt x r) dt = (r x a) . (dtheta_k - dtheta_{k-1}) / dt, of variance
  // 2 (r x a)^T C (r x a) / dt^2, C the covariance of the array's angle-increment estimate. A
  // MEMS triad 0.15 m off (0.228 deg/sqrt(h), 100 Hz) gets 0.081 mm/s per sample beside its own
  // 0.069 (70 ug/sqrt(Hz)): left out, the parity test's false alarms were 2.25 per hour on a
  // vibrating mount (seed000_triplex_mems_lever_arms.yaml). Taken per instrument, independent:
  // across units the term is correlated, and over a window its sum telescopes to two samples'
  // worth, so this is the larger, cautious figure (the minimum detectable bias the detector prints
  // includes it).
  const Channel& gyros = channel(ImuInstrument::kGyro);
  const Eigen::Vector3d lever = unit.lever_arm_b_m.cross(axis_b);
  if (!gyros.glr || lever.isZero(0.0)) return unit.accel_sigma_mps;
  const double arm_variance = 2.0 * lever.dot(gyros.glr->space().estimateCovariance() * lever) /
                              (interval_s_ * interval_s_);
  return std::sqrt(unit.accel_sigma_mps * unit.accel_sigma_mps + arm_variance);
}

bool ImuArrayParity::exclude(ImuInstrument kind, int unit, int axis) {
  Channel& c = channel(kind);
  const int target = 3 * unit + axis;
  int kept = 0;
  for (int r = 0; r < c.rows; ++r) {
    const auto row = static_cast<std::size_t>(r);
    if (c.instrument[row] == target) continue;
    c.instrument[static_cast<std::size_t>(kept)] = c.instrument[row];
    c.reference[kept] = c.reference[r];
    ++kept;
  }
  if (kept == c.rows) return testing(kind);
  c.rows = kept;
  c.reference.conservativeResize(kept);
  // The kept part of o still removes the biases' parity (o = P b + H c restricted is
  // b' - H'(-c) up to the new projector), so the mean need not be learned again.
  std::string error;
  return build(kind, error);
}

void ImuArrayParity::restart() {
  for (Channel& c : channels_)
    if (c.glr) c.glr->reset();
  have_previous_rate_ = false;
}

int ImuArrayParity::instruments(ImuInstrument kind) const {
  return channel(kind).rows;
}

double ImuArrayParity::threshold(ImuInstrument kind) const {
  const Channel& c = channel(kind);
  return c.glr ? c.glr->threshold() : 0.0;
}

double ImuArrayParity::minimumDetectableBias(ImuInstrument kind, int unit, int axis) const {
  const Channel& c = channel(kind);
  if (!c.glr) return 0.0;
  for (int r = 0; r < c.rows; ++r)
    if (c.instrument[static_cast<std::size_t>(r)] == 3 * unit + axis)
      return c.glr->minimumDetectableBias(r) / interval_s_;
  return 0.0;
}

void ImuArrayParity::fillGyro(const std::array<ImuIncrement, kMaxUnits>& increments) {
  Channel& c = channel(ImuInstrument::kGyro);
  c.m.resize(c.rows);
  for (int r = 0; r < c.rows; ++r) {
    const int i = c.instrument[static_cast<std::size_t>(r)];
    c.m[r] = increments[static_cast<std::size_t>(i / 3)].delta_angle_b_rad[i % 3];
  }
  // w: every gyro still in the array, the learned mean removed (the common bias left in it is
  // the array's, far below what the lever-arm term needs).
  if (c.glr) {
    const parity::Measurements corrected = c.m - c.reference;
    rate_b_radps_ = c.glr->space().estimate(corrected) / interval_s_;
  }
}

void ImuArrayParity::fillAccelerometer(const std::array<ImuIncrement, kMaxUnits>& increments) {
  Channel& c = channel(ImuInstrument::kAccelerometer);
  // Eq. 1's lever-arm term, first order: dw/dt from the previous sample's rate.
  const Eigen::Vector3d& w = rate_b_radps_;
  const Eigen::Vector3d w_dot = have_previous_rate_
                                    ? Eigen::Vector3d((w - previous_rate_b_radps_) / interval_s_)
                                    : Eigen::Vector3d::Zero();
  previous_rate_b_radps_ = w;
  have_previous_rate_ = true;
  c.m.resize(c.rows);
  for (int r = 0; r < c.rows; ++r) {
    const int i = c.instrument[static_cast<std::size_t>(r)];
    const ImuArrayUnit& unit = units_[static_cast<std::size_t>(i / 3)];
    const Eigen::Vector3d arm_f_b = leverArmSpecificForce(w, w_dot, unit.lever_arm_b_m);
    c.m[r] = increments[static_cast<std::size_t>(i / 3)].delta_vel_b_mps[i % 3] -
             unit.c_u_b.row(i % 3).dot(arm_f_b) * interval_s_;
  }
}

void ImuArrayParity::test(ImuInstrument kind) {
  Channel& c = channel(kind);
  auto& detection = result_.detections[static_cast<std::size_t>(kind)];
  detection.reset();
  result_.statistic[static_cast<std::size_t>(kind)] = 0.0;
  if (!c.glr) return;
  const ParitySpace& space = c.glr->space();
  const auto tracking = [&](double gain) {
    const parity::Measurements corrected = c.m - c.reference;
    const parity::Measurements residual = corrected - space.axes() * space.estimate(corrected);
    c.reference += gain * residual;
  };
  if (result_.learning) {
    tracking(1.0 / static_cast<double>(samples_));  // the running mean of the residual
    return;
  }
  const ParityGlrResult& r = c.glr->update(c.m - c.reference);
  result_.statistic[static_cast<std::size_t>(kind)] = r.statistic;
  if (r.detected) {
    detection = this->detection(kind);
  } else if (config_.reference_time_constant_samples > 0.0) {
    tracking(1.0 / config_.reference_time_constant_samples);
  }
}

std::optional<ImuArrayDetection> ImuArrayParity::detection(ImuInstrument kind) const {
  const Channel& c = channel(kind);
  const ParityGlrResult& r = c.glr->last();
  ImuArrayDetection d;
  d.kind = kind;
  d.glr = r;
  const int i = c.instrument[static_cast<std::size_t>(r.instrument)];
  d.unit = i / 3;
  d.axis = i % 3;
  d.magnitude = r.magnitude / interval_s_;
  d.magnitude_sigma = r.magnitude_sigma / interval_s_;
  if (r.runner_up >= 0) {
    const int j = c.instrument[static_cast<std::size_t>(r.runner_up)];
    d.runner_up_unit = j / 3;
    d.runner_up_axis = j % 3;
    d.runner_up_magnitude = r.runner_up_magnitude / interval_s_;
  }
  return d;
}

const ImuArrayParity::Result& ImuArrayParity::update(
    const std::array<ImuIncrement, kMaxUnits>& increments) {
  ++samples_;
  result_.learning = samples_ <= config_.reference_samples;
  fillGyro(increments);
  fillAccelerometer(increments);
  test(ImuInstrument::kGyro);
  test(ImuInstrument::kAccelerometer);
  return result_;
}

}  // namespace navbus::core
