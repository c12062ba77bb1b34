#include "navbus/core/spectrum.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>

namespace navbus::core {

std::vector<double> amplitudeSpectrum(const std::vector<double>& signal, double rate_hz) {
  (void)rate_hz;  // bins are k * rate / N; the amplitudes do not depend on the rate
  const std::size_t n = signal.size();
  if (n < 2) return {};
  std::vector<double> in(n);
  double window_sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double w =
        0.5 - 0.5 * std::cos(2.0 * M_PI * static_cast<double>(i) / static_cast<double>(n));
    in[i] = signal[i] * w;
    window_sum += w;
  }
  std::vector<fftw_complex> out(n / 2 + 1);
  // FFTW_ESTIMATE: no timing-dependent planning, so results are reproducible.
  fftw_plan plan = fftw_plan_dft_r2c_1d(static_cast<int>(n), in.data(), out.data(), FFTW_ESTIMATE);
  fftw_execute(plan);
  fftw_destroy_plan(plan);
  std::vector<double> amp(n / 2 + 1);
  for (std::size_t k = 0; k < amp.size(); ++k) {
    amp[k] = 2.0 * std::hypot(out[k][0], out[k][1]) / window_sum;
  }
  return amp;
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
