#include "navbus/core/integrity/dither_monitor.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace navbus::core {

namespace {
void require(bool ok, const char* field, double value, const char* rule) {
  if (!ok) {
    throw std::invalid_argument(std::string("dither monitor: ") + field + " = " +
                                std::to_string(value) + ": " + rule);
  }
}

void validate(const DitherMonitorConfig& c) {
  const double nyquist = c.sample_rate_hz / 2.0;
  require(c.sample_rate_hz > 0.0 && std::isfinite(c.sample_rate_hz), "sample_rate_hz",
          c.sample_rate_hz, "must be positive");
  require(c.window_samples >= 16, "window_samples", c.window_samples, "must be >= 16");
  require(c.hop_samples >= 1 && c.hop_samples <= c.window_samples, "hop_samples", c.hop_samples,
          "must be in [1, window_samples]");
  for (double f : c.dither_frequency_hz) {
    require(f > 0.0 && f < nyquist, "dither_frequency_hz", f, "must be in (0, rate / 2)");
  }
  require(c.tolerance_hz > 0.0, "tolerance_hz", c.tolerance_hz, "must be positive");
  require(c.accel_band_low_hz >= 0.0 && c.accel_band_low_hz < c.accel_band_high_hz,
          "accel_band_low_hz", c.accel_band_low_hz, "must be below accel_band_high_hz");
  require(c.accel_band_high_hz <= nyquist, "accel_band_high_hz", c.accel_band_high_hz,
          "must not exceed rate / 2");
  require(c.gyro_band_low_hz >= 0.0 && c.gyro_band_low_hz < c.gyro_band_high_hz, "gyro_band_low_hz",
          c.gyro_band_low_hz, "must be below gyro_band_high_hz");
  require(c.motion_band_low_hz >= 0.0 && c.motion_band_low_hz < c.motion_band_high_hz,
          "motion_band_low_hz", c.motion_band_low_hz, "must be below motion_band_high_hz");
  require(c.accel_min_amplitude_mps2 > 0.0, "accel_min_amplitude_mps2", c.accel_min_amplitude_mps2,
          "must be positive");
  require(c.gyro_min_amplitude_radps > 0.0, "gyro_min_amplitude_radps", c.gyro_min_amplitude_radps,
          "must be positive");
  require(c.still_max_rms_mps2 > 0.0, "still_max_rms_mps2", c.still_max_rms_mps2,
          "must be positive");
  require(c.windows_to_fail >= 1, "windows_to_fail", c.windows_to_fail, "must be >= 1");
  require(c.windows_to_clear >= 1, "windows_to_clear", c.windows_to_clear, "must be >= 1");
}
}  // namespace

DitherMonitor::DitherMonitor(const DitherMonitorConfig& config)
    : config_((validate(config), config)),
      bin_hz_(config.sample_rate_hz / config.window_samples),
      period_ns_(std::llround(1e9 / config.sample_rate_hz)),
      fft_(static_cast<std::size_t>(config.window_samples)),
      time_ring_(static_cast<std::size_t>(config.window_samples)) {
  for (auto& r : ring_) r.assign(static_cast<std::size_t>(config.window_samples), 0.0);
  const auto& f = config.dither_frequency_hz;
  for (int i = 0; i < 3; ++i) {
    expected_hz_[static_cast<std::size_t>(i)] = f;
    // Gyro i carries the trapping lines |f_i - f_j| of the two other gyros (eq. 2).
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    expected_hz_[static_cast<std::size_t>(kFirstGyroChannel + i)] = {
        std::abs(f[static_cast<std::size_t>(i)] - f[static_cast<std::size_t>(j)]),
        std::abs(f[static_cast<std::size_t>(i)] - f[static_cast<std::size_t>(k)]), 0.0};
  }
}

const DitherWindow* DitherMonitor::addSample(std::int64_t time_ns,
                                             const Eigen::Vector3d& specific_force_mps2,
                                             const Eigen::Vector3d& angular_rate_radps) {
  if (last_time_ns_ >= 0) {
    const std::int64_t dt = time_ns - last_time_ns_;
    if (dt <= 0) {
      ++counters_.refused;
      return nullptr;
    }
    if (std::abs(dt - period_ns_) > period_ns_ / 2) {  // a gap (or a rate change): start over
      ++counters_.gaps;
      if (filled_ > 0) ++counters_.windows_dropped;
      filled_ = 0;
      since_window_ = 0;
      for (auto& s : state_) s.failing = s.passing = 0;
    }
  }
  last_time_ns_ = time_ns;
  ++counters_.samples;
  for (int a = 0; a < 3; ++a) {
    ring_[static_cast<std::size_t>(a)][head_] = specific_force_mps2[a];
    ring_[static_cast<std::size_t>(kFirstGyroChannel + a)][head_] = angular_rate_radps[a];
  }
  time_ring_[head_] = time_ns;
  const auto n = static_cast<std::size_t>(config_.window_samples);
  head_ = (head_ + 1) % n;
  if (filled_ < n) ++filled_;
  ++since_window_;
  if (filled_ < n || since_window_ < static_cast<std::size_t>(config_.hop_samples)) return nullptr;
  since_window_ = 0;
  analyse();
  return &window_;
}

void DitherMonitor::analyse() {
  ++counters_.windows;
  window_.start_time_ns = time_ring_[head_];  // oldest sample: the slot written next
  window_.end_time_ns = last_time_ns_;
  window_.changed.fill(false);
  window_.motion_rms_mps2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    window_.check[static_cast<std::size_t>(a)] =
        checkChannel(a, config_.accel_band_low_hz, config_.accel_band_high_hz);
    window_.motion_rms_mps2 = std::max(
        window_.motion_rms_mps2, bandRms(config_.motion_band_low_hz, config_.motion_band_high_hz));
    updateState(a);
  }
  // A failed accelerometer cannot vouch for stillness (a stuck output is perfectly quiet).
  bool accels_healthy = true;
  for (int a = 0; a < 3; ++a) accels_healthy = accels_healthy && !failed(a);
  window_.still = accels_healthy && window_.motion_rms_mps2 < config_.still_max_rms_mps2;
  for (int g = kFirstGyroChannel; g < kDitherChannels; ++g) {
    if (config_.check_gyros && window_.still) {
      window_.check[static_cast<std::size_t>(g)] =
          checkChannel(g, config_.gyro_band_low_hz, config_.gyro_band_high_hz);
      updateState(g);
    } else {
      window_.check[static_cast<std::size_t>(g)] = DitherChannelCheck{};
    }
  }
  if (config_.check_gyros && !window_.still) ++counters_.gyro_windows_skipped;
}

DitherChannelCheck DitherMonitor::checkChannel(int channel, double low_hz, double high_hz) {
  const auto& ring = ring_[static_cast<std::size_t>(channel)];
  const std::size_t n = ring.size();
  double* in = fft_.input();
  // Oldest first, with the window's mean removed: the Hann window's main lobe would spread
  // gravity (DC) into the lowest bins of the motion band.
  double mean = 0.0;
  for (double v : ring) mean += v;
  mean /= static_cast<double>(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = ring[(head_ + i) % n] - mean;
  const std::vector<double>& spectrum = fft_.compute();
  DitherChannelCheck c;
  c.checked = true;
  c.distance_hz = std::numeric_limits<double>::infinity();
  const auto peak = largestPeak(spectrum, bin_hz_, low_hz, high_hz);
  if (!peak) return c;
  c.peak_frequency_hz = peak->frequency_hz;
  c.peak_amplitude = peak->amplitude;
  for (double f : expectedHz(channel)) {
    if (f > 0.0) c.distance_hz = std::min(c.distance_hz, std::abs(peak->frequency_hz - f));
  }
  c.passed = c.distance_hz <= config_.tolerance_hz && c.peak_amplitude >= minAmplitude(channel);
  return c;
}

double DitherMonitor::bandRms(double low_hz, double high_hz) const {
  // With the Hann window and the amplitude scaling of SpectrumAnalyzer, white noise gives
  // E[A_k^2] = 3 sigma_band^2 / B over a band of B bins, and a sinusoid of amplitude A gives
  // sum A_k^2 = 1.5 A^2 over its main lobe: RMS^2 = sum A_k^2 / 3 for both.
  const auto& spectrum = fft_.amplitudes();
  double sum = 0.0;
  for (std::size_t k = 1; k < spectrum.size(); ++k) {
    const double f = static_cast<double>(k) * bin_hz_;
    if (f >= low_hz && f <= high_hz) sum += spectrum[k] * spectrum[k];
  }
  return std::sqrt(sum / 3.0);
}

void DitherMonitor::updateState(int channel) {
  auto& s = state_[static_cast<std::size_t>(channel)];
  const DitherChannelCheck& c = window_.check[static_cast<std::size_t>(channel)];
  bool failed = s.failed;
  if (c.passed) {
    s.failing = 0;
    ++s.passing;
    s.last_passed_start_ns = window_.start_time_ns;
    if (s.passing >= config_.windows_to_clear) failed = false;
  } else {
    s.passing = 0;
    ++s.failing;
    if (s.failing >= config_.windows_to_fail) failed = true;
  }
  window_.changed[static_cast<std::size_t>(channel)] = failed != s.failed;
  s.failed = failed;
}

}  // namespace navbus::core
