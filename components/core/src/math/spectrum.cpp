#include "navbus/core/math/spectrum.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace navbus::core {

SpectrumAnalyzer::SpectrumAnalyzer(std::size_t window_samples)
    : n_(window_samples), window_(window_samples), amplitude_(window_samples / 2 + 1) {
  if (n_ < 4) throw std::invalid_argument("SpectrumAnalyzer: window_samples must be >= 4");
  in_ = fftw_alloc_real(n_);
  out_ = fftw_alloc_complex(n_ / 2 + 1);
  plan_ = fftw_plan_dft_r2c_1d(static_cast<int>(n_), in_, static_cast<fftw_complex*>(out_),
                               FFTW_ESTIMATE);
  for (std::size_t i = 0; i < n_; ++i) {
    window_[i] =
        0.5 - 0.5 * std::cos(2.0 * M_PI * static_cast<double>(i) / static_cast<double>(n_));
    window_sum_ += window_[i];
  }
}

SpectrumAnalyzer::~SpectrumAnalyzer() {
  fftw_destroy_plan(static_cast<fftw_plan>(plan_));
  fftw_free(out_);
  fftw_free(in_);
}

const std::vector<double>& SpectrumAnalyzer::compute() {
  for (std::size_t i = 0; i < n_; ++i) in_[i] *= window_[i];
  fftw_execute(static_cast<fftw_plan>(plan_));
  const auto* out = static_cast<const fftw_complex*>(out_);
  for (std::size_t k = 0; k < amplitude_.size(); ++k) {
    amplitude_[k] = 2.0 * std::hypot(out[k][0], out[k][1]) / window_sum_;
  }
  return amplitude_;
}

std::vector<double> amplitudeSpectrum(const std::vector<double>& signal, double rate_hz) {
  (void)rate_hz;  // bins are k * rate / N; the amplitudes do not depend on the rate
  if (signal.size() < 4) return {};
  SpectrumAnalyzer analyzer(signal.size());
  std::copy(signal.begin(), signal.end(), analyzer.input());
  return analyzer.compute();
}

std::optional<SpectralPeak> largestPeak(const std::vector<double>& spectrum, double bin_hz,
                                        double lo_hz, double hi_hz) {
  std::optional<SpectralPeak> best;
  const auto first = static_cast<std::size_t>(std::max(1.0, std::ceil(lo_hz / bin_hz)));
  const auto last = std::min(spectrum.size() - 1, static_cast<std::size_t>(hi_hz / bin_hz) + 1);
  for (std::size_t k = first; k < last; ++k) {
    if (static_cast<double>(k) * bin_hz > hi_hz) break;
    const bool local_max = spectrum[k] > spectrum[k - 1] && spectrum[k] >= spectrum[k + 1];
    if (local_max && (!best || spectrum[k] > best->amplitude))
      best = SpectralPeak{static_cast<double>(k) * bin_hz, spectrum[k]};
  }
  return best;
}

std::vector<SpectralPeak> largestPeaks(const std::vector<double>& spectrum, double rate_hz,
                                       std::size_t signal_length, double lo_hz, double hi_hz,
                                       std::size_t count) {
  const double bin_hz = rate_hz / static_cast<double>(signal_length);
  std::vector<SpectralPeak> peaks;
  for (std::size_t k = 1; k + 1 < spectrum.size(); ++k) {
    const double f = static_cast<double>(k) * bin_hz;
    if (f < lo_hz || f > hi_hz) continue;
    if (spectrum[k] > spectrum[k - 1] && spectrum[k] >= spectrum[k + 1])
      peaks.push_back({f, spectrum[k]});
  }
  std::sort(peaks.begin(), peaks.end(),
            [](const auto& a, const auto& b) { return a.amplitude > b.amplitude; });
  if (peaks.size() > count) peaks.resize(count);
  return peaks;
}

}  // namespace navbus::core
