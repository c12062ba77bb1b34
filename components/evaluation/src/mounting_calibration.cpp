#include "navbus/evaluation/mounting_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <tuple>
#include <utility>

#include <fmt/format.h>

#include "navbus/bus/config.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/evaluation/recording_runner.hpp"

namespace navbus::evaluation {

namespace {

/// The q-quantile of `values` (nearest rank); `values` is reordered.
double quantile(std::vector<double>& values, double q) {
  const auto k = static_cast<std::size_t>(std::lround(q * static_cast<double>(values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

/// The course of the velocity [rad from north].
double courseOf(const core::SmoothedEpoch& e) {
  return std::atan2(e.state.vel_ned_mps.y(), e.state.vel_ned_mps.x());
}

/// Change of the course per second between two epochs (the difference wrapped to (-pi, pi]).
double headingRate(const core::SmoothedEpoch& a, const core::SmoothedEpoch& b) {
  const double dt = 1e-9 * static_cast<double>(b.time_ns - a.time_ns);
  if (!(dt > 0.0)) return 0.0;
  return std::remainder(courseOf(b) - courseOf(a), 2.0 * M_PI) / dt;
}

/// The change of speed per second over about +-0.5 s around epoch i (both neighbours smoothed
/// and within 1.5 s); nullopt where the epochs do not reach that far.
std::optional<double> longitudinalAcceleration(const std::vector<core::SmoothedEpoch>& epochs,
                                               std::size_t i) {
  constexpr std::int64_t kHalf = 500'000'000, kFar = 1'500'000'000;
  const std::int64_t t = epochs[i].time_ns;
  std::size_t j = i, k = i;
  while (j > 0 && t - epochs[j].time_ns < kHalf) --j;
  while (k + 1 < epochs.size() && epochs[k].time_ns - t < kHalf) ++k;
  const std::int64_t before = t - epochs[j].time_ns, after = epochs[k].time_ns - t;
  if (before < kHalf || after < kHalf || before > kFar || after > kFar) return std::nullopt;
  if (!epochs[j].smoothed || !epochs[k].smoothed) return std::nullopt;
  return (epochs[k].state.vel_ned_mps.norm() - epochs[j].state.vel_ned_mps.norm()) /
         (1e-9 * static_cast<double>(epochs[k].time_ns - epochs[j].time_ns));
}

/// Least-squares slope of y on x and the correlation coefficient (0, 0 below 3 points).
std::pair<double, double> slopeAndCorrelation(const std::vector<double>& x,
                                              const std::vector<double>& y) {
  if (x.size() < 3) return {0.0, 0.0};
  const auto n = static_cast<double>(x.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;
  double sxx = 0.0, syy = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (!(sxx > 0.0) || !(syy > 0.0)) return {0.0, 0.0};
  return {sxy / sxx, sxy / std::sqrt(sxx * syy)};
}

}  // namespace

MountingResidual mountingResidual(const std::vector<core::SmoothedEpoch>& epochs,
                                  const StraightDriving& straight) {
  std::vector<double> pitch, yaw, accel, accel_pitch;
  for (std::size_t i = 1; i < epochs.size(); ++i) {
    const core::SmoothedEpoch& e = epochs[i];
    if (!e.smoothed || !epochs[i - 1].smoothed) continue;
    if (e.state.vel_ned_mps.norm() < straight.min_speed_mps) continue;
    if (std::abs(headingRate(epochs[i - 1], e)) > straight.max_heading_rate_radps) continue;
    const Eigen::Vector3d v_b = e.state.q_b_to_n.conjugate() * e.state.vel_ned_mps;
    // Forward, right, down: climbing in body axes is a negative z component.
    pitch.push_back(std::atan2(-v_b.z(), std::hypot(v_b.x(), v_b.y())));
    yaw.push_back(std::atan2(v_b.y(), v_b.x()));
    if (const auto a = longitudinalAcceleration(epochs, i)) {
      accel.push_back(*a);
      accel_pitch.push_back(pitch.back());
    }
  }
  MountingResidual r;
  r.epochs = pitch.size();
  if (pitch.empty()) return r;
  std::tie(r.velocity_pitch_per_accel_rad_per_mps2, r.velocity_pitch_accel_correlation) =
      slopeAndCorrelation(accel, accel_pitch);
  r.pitch_rad = quantile(pitch, 0.5);
  r.pitch_q1_rad = quantile(pitch, 0.25);
  r.pitch_q3_rad = quantile(pitch, 0.75);
  r.yaw_rad = quantile(yaw, 0.5);
  r.yaw_q1_rad = quantile(yaw, 0.25);
  r.yaw_q3_rad = quantile(yaw, 0.75);
  // Body to vehicle axes: R^T, R = Rz(yaw) Ry(pitch) (correctedMountingRpy).
  const Eigen::Matrix3d to_vehicle =
      core::dcmFromEuler(Eigen::Vector3d(0.0, r.pitch_rad, r.yaw_rad)).transpose();
  Eigen::Vector2d configured = Eigen::Vector2d::Zero(), corrected = Eigen::Vector2d::Zero();
  for (const core::SmoothedEpoch& e : epochs) {
    if (!e.smoothed || e.state.vel_ned_mps.norm() < straight.min_speed_mps) continue;
    const Eigen::Vector3d v_b = e.state.q_b_to_n.conjugate() * e.state.vel_ned_mps;
    configured += v_b.tail<2>().cwiseAbs2();
    corrected += (to_vehicle * v_b).tail<2>().cwiseAbs2();
    ++r.moving_epochs;
  }
  const double n = static_cast<double>(r.moving_epochs);
  r.configured_rms_mps = (configured / n).cwiseSqrt();
  r.corrected_rms_mps = (corrected / n).cwiseSqrt();
  return r;
}

Eigen::Vector3d correctedMountingRpy(const Eigen::Matrix3d& sensor_to_body,
                                     const MountingResidual& residual) {
  // The vehicle's forward axis in body axes is R x, R = Rz(yaw) Ry(pitch); the vehicle's axes
  // are the body's turned by R: body-to-vehicle R^T. The new sensor-to-body rotation is
  // R^T C_s_b, and the angles' rotation (body to sensor, ImuMounting) its transpose C_b_s R.
  const Eigen::Matrix3d R =
      core::dcmFromEuler(Eigen::Vector3d(0.0, residual.pitch_rad, residual.yaw_rad));
  return core::eulerFromDcm(sensor_to_body.transpose() * R);
}

void configureMountingRun(RecordingSetup& setup) {
  setup.smooth = true;
  setup.withhold = {};
  setup.filter.engine.consistency.inflate_imu_biases_on_alarm = false;
}

int runMountingCommand(const MountingOptions& o) {
  ImportedRun imported = importForRun(o.dataset, o.filter, o.out_dir);
  RecordingSetup& setup = imported.setup;
  configureMountingRun(setup);
  const RecordingResult run = runRecording(setup);
  const MountingResidual r = mountingResidual(run.smoothed, o.straight);
  std::string text = imported.import_text;
  if (r.epochs == 0) {
    text += fmt::format(
        "no smoothed epoch above {:.1f} m/s with a heading rate below {:.2f} deg/s: nothing to "
        "calibrate on\n",
        o.straight.min_speed_mps, o.straight.max_heading_rate_radps / units::kDeg);
    std::fputs(text.c_str(), stdout);
    return 1;
  }
  const Eigen::Vector3d rpy =
      correctedMountingRpy(setup.filter.imu_mounting.sensor_to_body, r) / units::kDeg;
  text += fmt::format(
      "the vehicle's forward axis in body axes, over {} smoothed epochs driven straight (above "
      "{:.1f} m/s, heading rate below {:.2f} deg/s):\n"
      "  pitch {:+.3f} deg (quartiles {:+.3f} .. {:+.3f}), yaw {:+.3f} deg (quartiles {:+.3f} .. "
      "{:+.3f})\n"
      "the velocity across and below the forward axis over {} smoothed epochs above {:.1f} m/s "
      "(turns included), RMS: {:.3f} / {:.3f} m/s in the configured axes, {:.3f} / {:.3f} m/s "
      "corrected (what multi_dimensional.nhc_sigma_mps has to allow)\n"
      "the velocity's pitch in body axes against the longitudinal acceleration (straight "
      "epochs): {:+.3f} deg per m/s^2 (correlation {:+.2f})\n"
      "geometry:\n  imu_mounting_rpy_deg: [{:.2f}, {:.2f}, {:.2f}]\n"
      "multi_dimensional:\n  nhc_velocity_pitch_per_accel_deg_per_mps2: {:.3f}\n",
      r.epochs, o.straight.min_speed_mps, o.straight.max_heading_rate_radps / units::kDeg,
      r.pitch_rad / units::kDeg, r.pitch_q1_rad / units::kDeg, r.pitch_q3_rad / units::kDeg,
      r.yaw_rad / units::kDeg, r.yaw_q1_rad / units::kDeg, r.yaw_q3_rad / units::kDeg,
      r.moving_epochs, o.straight.min_speed_mps, r.configured_rms_mps.x(), r.configured_rms_mps.y(),
      r.corrected_rms_mps.x(), r.corrected_rms_mps.y(),
      r.velocity_pitch_per_accel_rad_per_mps2 / units::kDeg, r.velocity_pitch_accel_correlation,
      rpy.x(), rpy.y(), rpy.z(), r.velocity_pitch_per_accel_rad_per_mps2 / units::kDeg);
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace navbus::evaluation
