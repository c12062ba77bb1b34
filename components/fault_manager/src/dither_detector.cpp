#include "navbus/fault_manager/dither_detector.hpp"

#include <cmath>
#include <sstream>

#include <spdlog/spdlog.h>

namespace navbus::fault_manager {

DitherDetector::DitherDetector(const DitherDetectorConfig& config)
    : config_(config),
      monitor_(config.monitor),
      period_ns_(std::llround(1e9 / config.monitor.sample_rate_hz)) {}

void DitherDetector::onRawBlock(const navbus::ImuRawBlock& block, FaultOutput& out) {
  if (block.sensor_id() != config_.imu_id) {
    ++counters_.other_imus;
    return;
  }
  // A block at another rate is another sensor than the one configured: its lines cannot be
  // compared (1 ns of rounding allowed).
  if (std::llabs(static_cast<long long>(block.sample_period_ns()) - period_ns_) > 1) {
    if (counters_.wrong_rate++ == 0) {
      spdlog::warn(
          "dither monitor: IMU {} raw samples every {} ns, configured {} Hz: not monitored",
          block.sensor_id(), block.sample_period_ns(), config_.monitor.sample_rate_hz);
    }
    return;
  }
  if (auto r = bus::validate(block, limits_)) {
    ++counters_.invalid;  // the monitor sees a gap where this block was
    return;
  }
  ++counters_.blocks;
  const auto t0 = static_cast<std::int64_t>(block.first_sample_time_gps_ns());
  const auto dt = static_cast<std::int64_t>(block.sample_period_ns());
  for (std::size_t i = 0; i < block.samples().size(); ++i) {
    const auto& s = block.samples()[i];
    const Eigen::Vector3d f(s.specific_force_b_mps2()[0], s.specific_force_b_mps2()[1],
                            s.specific_force_b_mps2()[2]);
    const Eigen::Vector3d w(s.angular_rate_b_radps()[0], s.angular_rate_b_radps()[1],
                            s.angular_rate_b_radps()[2]);
    const core::DitherWindow* win =
        monitor_.addSample(t0 + static_cast<std::int64_t>(i) * dt, f, w);
    if (!win) continue;
    for (int c = 0; c < core::kDitherChannels; ++c) {
      if (win->changed[static_cast<std::size_t>(c)]) report(c, *win, out);
    }
  }
}

void DitherDetector::report(int channel, const core::DitherWindow& w, FaultOutput& out) {
  const bool failed = monitor_.failed(channel);
  const bool accel = channel < core::kFirstGyroChannel;
  const auto axis = static_cast<std::uint16_t>(channel % 3);
  const core::DitherChannelCheck& check = w.check[static_cast<std::size_t>(channel)];
  navbus::FaultDecision d;
  d.time_gps_ns(static_cast<std::uint64_t>(w.end_time_ns));
  d.event(failed ? navbus::EVENT_FAULT_DETECTED : navbus::EVENT_FAULT_CLEARED);
  d.source(accel ? navbus::SOURCE_ACCELEROMETER : navbus::SOURCE_GYRO);
  d.sensor_id(config_.imu_id);
  d.axis(axis);
  d.shape(navbus::SHAPE_NONE);
  d.test_statistic(check.distance_hz);
  d.threshold(config_.monitor.tolerance_hz);
  // The fault began after the start of the newest window the channel passed.
  const std::int64_t passed = monitor_.lastPassedStartNs(channel);
  d.onset_time_gps_ns(static_cast<std::uint64_t>(passed >= 0 ? passed : w.start_time_ns));
  d.detector("dither-fft");
  navbus::DitherEvidence& e = d.dither();
  e.peak_frequency_hz(check.peak_frequency_hz);
  e.peak_amplitude(check.peak_amplitude);
  e.min_amplitude(monitor_.minAmplitude(channel));
  const auto& expected = monitor_.expectedHz(channel);
  for (std::size_t i = 0; i < 3; ++i) e.expected_frequency_hz()[i] = expected[i];
  e.tolerance_hz(config_.monitor.tolerance_hz);
  e.window_s(config_.monitor.window_samples / config_.monitor.sample_rate_hz);
  const std::uint32_t id = out.decide(d);
  (failed ? counters_.detections : counters_.cleared)++;
  spdlog::warn(
      "decision {}: dither-fft {} {} {}: largest peak {:.1f} Hz, {:.3g} (expected {:.0f} "
      "{:.0f} {:.0f} Hz +- {:.0f} Hz, >= {:.3g})",
      id, accel ? "accelerometer" : "gyro", "xyz"[axis], failed ? "FAILED" : "cleared",
      check.peak_frequency_hz, check.peak_amplitude, expected[0], expected[1], expected[2],
      config_.monitor.tolerance_hz, monitor_.minAmplitude(channel));
  if (!failed || !config_.fail_axes) return;
  navbus::FilterCommand c = failAxisCommand(d);  // decide() stamped its id
  out.command(c);
}

std::string DitherDetector::summary() const {
  const auto& m = monitor_.counters();
  std::ostringstream s;
  s << "dither-fft: " << counters_.blocks << " raw blocks, " << m.windows << " windows ("
    << m.windows_dropped << " dropped at " << m.gaps << " gaps, gyros skipped while moving "
    << m.gyro_windows_skipped << "), axes failed " << counters_.detections << ", cleared "
    << counters_.cleared;
  if (counters_.other_imus + counters_.wrong_rate + counters_.invalid + m.refused > 0) {
    s << "; not monitored: other IMUs " << counters_.other_imus << ", other rate "
      << counters_.wrong_rate << ", invalid " << counters_.invalid << ", samples out of order "
      << m.refused;
  }
  return s.str();
}

}  // namespace navbus::fault_manager
