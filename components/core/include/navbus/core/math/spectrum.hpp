// Amplitude spectra of real signals (FFTW), for the dither monitor (seed 003) and its tests.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace navbus::core {

struct SpectralPeak {
  double frequency_hz;
  double amplitude;  ///< amplitude of the sinusoid at that frequency (same unit as the signal)
};

/// One-sided amplitude spectrum of windows of a fixed length N, with a Hann window and the
/// window gain removed so that a sinusoid of amplitude A on a bin shows about A (bin k at
/// k * rate / N). The FFTW plan and every buffer are made once, in the constructor:
/// compute() allocates nothing. FFTW plans with FFTW_ESTIMATE (no timing-dependent planning,
/// so results are reproducible). Not thread-safe: FFTW's planner is not, so make analyzers on
/// one thread.
class SpectrumAnalyzer {
 public:
  explicit SpectrumAnalyzer(std::size_t window_samples);
  ~SpectrumAnalyzer();
  SpectrumAnalyzer(const SpectrumAnalyzer&) = delete;
  SpectrumAnalyzer& operator=(const SpectrumAnalyzer&) = delete;

  std::size_t windowSamples() const { return n_; }
  /// Input buffer of windowSamples() values: fill it (un-windowed), then call compute().
  double* input() { return in_; }
  /// The amplitude spectrum of input(), N/2 + 1 bins. input() is overwritten.
  const std::vector<double>& compute();
  const std::vector<double>& amplitudes() const { return amplitude_; }

 private:
  std::size_t n_;
  double* in_;
  void* out_;   // fftw_complex[N/2 + 1]
  void* plan_;  // fftw_plan
  std::vector<double> window_;
  double window_sum_{0.0};
  std::vector<double> amplitude_;
};

/// One-off spectrum of a whole signal (plans for its length; for analysis and tests, not for
/// streaming).
std::vector<double> amplitudeSpectrum(const std::vector<double>& signal, double rate_hz);

/// The largest local maximum of `spectrum` (bins of width bin_hz) between lo_hz and hi_hz;
/// none if the band holds no local maximum. Allocates nothing.
std::optional<SpectralPeak> largestPeak(const std::vector<double>& spectrum, double bin_hz,
                                        double lo_hz, double hi_hz);

/// The `count` largest local maxima of the spectrum between lo_hz and hi_hz, largest first.
std::vector<SpectralPeak> largestPeaks(const std::vector<double>& spectrum, double rate_hz,
                                       std::size_t signal_length, double lo_hz, double hi_hz,
                                       std::size_t count);

}  // namespace navbus::core
