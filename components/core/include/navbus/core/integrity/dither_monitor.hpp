// Ring-laser-gyro dither monitor (seed 003, Yoo and Kim): a missing dither line in the raw
// high-rate output means the signal chain of that axis (sensor, electronics, computer) failed.
//
// Signal model (seed 003 eqs. 1-2): each accelerometer sees the dither of all three gyros at
// f_x, f_y, f_z (its own axis weaker); with lock-in trapping, each gyro output carries the
// difference frequencies |f_i - f_j|. Method (seed 003, section 3): buffer each axis, take the
// FFT of a window, find the largest peak in the dither band (300-1200 Hz for accelerometers),
// and compare its frequency with the stored dither frequencies within a tolerance; any of the
// three counts as healthy, because the largest peak moves with the random dither amplitudes.
// Gyros are checked on the difference frequencies, and only while the vehicle is still: the
// difference lines (30-70 Hz) collide with vehicle motion (seed 003, vehicle test). Stillness is
// taken from the same spectra: the accelerometers' RMS in the vehicle-motion band below a
// threshold, with every accelerometer healthy (a stuck one is quiet whatever the vehicle does).
//
// A peak also has to reach a minimum amplitude: a stuck (constant) output has no lines at all,
// and the largest "peak" of its numerical noise could fall on a dither frequency by chance.
// An axis is declared failed after `windows_to_fail` consecutive failing windows, and healthy
// again after `windows_to_clear` consecutive passing ones (one fault bit per axis).
//
// Windows are taken every `hop_samples` over the last `window_samples` samples. A gap in the
// sample times (a lost block, a restarted stream) never makes a false alarm: the samples
// before the gap are discarded (the window being filled is dropped and counted) and the
// consecutive-failure counts restart.
//
// Allocation happens in the constructor only: addSample() allocates nothing.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "navbus/core/math/spectrum.hpp"

namespace navbus::core {

struct DitherMonitorConfig {
  double sample_rate_hz{2400.0};
  int window_samples{512};  ///< FFT length (0.213 s at 2400 Hz; bins of 4.7 Hz)
  int hop_samples{128};     ///< a window every hop (75 % overlap at the defaults)
  std::array<double, 3> dither_frequency_hz{373.0, 441.0, 409.0};  ///< gyros x, y, z
  double tolerance_hz{10.0};  ///< allowed distance of a peak from a stored frequency
  // Accelerometers: the dither band and the smallest dither line accepted.
  double accel_band_low_hz{300.0};
  double accel_band_high_hz{1200.0};
  double accel_min_amplitude_mps2{1e-3};
  // Gyros: the difference-frequency band, checked while still only.
  bool check_gyros{true};
  double gyro_band_low_hz{20.0};
  double gyro_band_high_hz{100.0};
  double gyro_min_amplitude_radps{1e-3};
  // Stillness: accelerometer RMS in the vehicle-motion band.
  double motion_band_low_hz{1.0};
  double motion_band_high_hz{60.0};
  double still_max_rms_mps2{0.01};
  int windows_to_fail{2};
  int windows_to_clear{4};
};

/// Channels: accelerometers x, y, z then gyros x, y, z.
inline constexpr int kDitherChannels = 6;
inline constexpr int kFirstGyroChannel = 3;

struct DitherChannelCheck {
  bool checked{false};  ///< false: not tested in this window (a gyro while the vehicle moves)
  bool passed{false};
  double peak_frequency_hz{0.0};  ///< largest peak in the channel's band; 0 if none
  double peak_amplitude{0.0};     ///< its amplitude [m/s^2 or rad/s]
  double distance_hz{0.0};        ///< from the nearest expected frequency (inf without a peak)
};

/// One analysed window: the checks, and which channels changed state with it.
struct DitherWindow {
  std::int64_t start_time_ns{0};  ///< time of the window's first sample
  std::int64_t end_time_ns{0};    ///< time of its last sample
  bool still{false};              ///< motion-band RMS below the threshold: gyros checked
  double motion_rms_mps2{0.0};    ///< largest accelerometer RMS in the motion band
  std::array<DitherChannelCheck, kDitherChannels> check{};
  std::array<bool, kDitherChannels> changed{};  ///< the channel's fault bit changed here
};

class DitherMonitor {
 public:
  /// Throws std::invalid_argument naming the field for an inconsistent configuration.
  explicit DitherMonitor(const DitherMonitorConfig& config);

  /// One raw sample at time_ns [GPS ns]: specific force [m/s^2] and angular rate [rad/s], body.
  /// Returns the window analysed with this sample, or nullptr. A sample not after the previous
  /// one is refused and counted.
  const DitherWindow* addSample(std::int64_t time_ns, const Eigen::Vector3d& specific_force_mps2,
                                const Eigen::Vector3d& angular_rate_radps);

  bool failed(int channel) const { return state_[static_cast<std::size_t>(channel)].failed; }
  /// Start of the newest window the channel passed (the fault began after it); -1 if none yet.
  std::int64_t lastPassedStartNs(int channel) const {
    return state_[static_cast<std::size_t>(channel)].last_passed_start_ns;
  }
  /// The frequencies a channel's peak is compared with [Hz]; 0 marks an unused entry (a gyro
  /// has two difference frequencies).
  const std::array<double, 3>& expectedHz(int channel) const {
    return expected_hz_[static_cast<std::size_t>(channel)];
  }
  double minAmplitude(int channel) const {
    return channel < kFirstGyroChannel ? config_.accel_min_amplitude_mps2
                                       : config_.gyro_min_amplitude_radps;
  }
  const DitherMonitorConfig& config() const { return config_; }

  struct Counters {
    std::uint64_t samples{0}, refused{0}, windows{0};
    std::uint64_t gaps{0}, windows_dropped{0};  ///< windows lost to gaps in the sample times
    std::uint64_t gyro_windows_skipped{0};      ///< windows with the vehicle moving
  };
  const Counters& counters() const { return counters_; }

 private:
  struct ChannelState {
    bool failed{false};
    int failing{0}, passing{0};
    std::int64_t last_passed_start_ns{-1};
  };
  void analyse();
  DitherChannelCheck checkChannel(int channel, double low_hz, double high_hz);
  double bandRms(double low_hz, double high_hz) const;
  void updateState(int channel);

  DitherMonitorConfig config_;
  std::array<std::array<double, 3>, kDitherChannels> expected_hz_{};
  double bin_hz_;
  std::int64_t period_ns_;
  SpectrumAnalyzer fft_;
  // Ring buffers: one window of each channel, and the sample times.
  std::array<std::vector<double>, kDitherChannels> ring_;
  std::vector<std::int64_t> time_ring_;
  std::size_t head_{0};    ///< next slot to write
  std::size_t filled_{0};  ///< valid samples since the last gap (<= window)
  std::size_t since_window_{0};
  std::int64_t last_time_ns_{-1};
  std::array<ChannelState, kDitherChannels> state_{};
  DitherWindow window_;
  Counters counters_;
};

}  // namespace navbus::core
