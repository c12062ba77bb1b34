// Amplitude spectrum of a real signal (FFTW), for dither monitoring and its tests.
#pragma once

#include <vector>

namespace navbus::core {

struct SpectralPeak {
  double frequency_hz;
  double amplitude;  ///< amplitude of the sinusoid at that frequency (same unit as the signal)
};

/// One-sided amplitude spectrum of `signal` sampled at `rate_hz` (bin k at k * rate / N), with a
/// Hann window and the window gain removed so a sinusoid of amplitude A shows about A.
std::vector<double> amplitudeSpectrum(const std::vector<double>& signal, double rate_hz);

/// The `count` largest local maxima of the spectrum between lo_hz and hi_hz, largest first.
std::vector<SpectralPeak> largestPeaks(const std::vector<double>& spectrum, double rate_hz,
                                       std::size_t signal_length, double lo_hz, double hi_hz,
                                       std::size_t count);

}  // namespace navbus::core
