// The raw stream's spectrum shows the dither frequencies and, in the gyros, their differences.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "navbus/core/math/spectrum.hpp"
#include "navbus/sim/dither.hpp"

namespace {
constexpr double kRate = 2400.0;

std::vector<double> series(const navbus::sim::DitherModel& m, bool gyro, int axis, double seconds) {
  std::vector<double> out;
  for (int k = 0; k < static_cast<int>(seconds * kRate); ++k) {
    const auto d = m.at(k / kRate);
    out.push_back(gyro ? d.angular_rate_b_radps[axis] : d.specific_force_b_mps2[axis]);
  }
  return out;
}

bool hasPeakNear(const std::vector<navbus::core::SpectralPeak>& peaks, double f, double tol) {
  return std::any_of(peaks.begin(), peaks.end(),
                     [&](const auto& p) { return std::abs(p.frequency_hz - f) <= tol; });
}
}  // namespace

TEST(Dither, AccelerometersShowAllThreeDitherFrequencies) {
  navbus::sim::DitherModel m({});
  for (int axis = 0; axis < 3; ++axis) {
    const auto x = series(m, false, axis, 1.0);
    const auto peaks = navbus::core::largestPeaks(navbus::core::amplitudeSpectrum(x, kRate), kRate,
                                                  x.size(), 300, 1200, 3);
    ASSERT_EQ(peaks.size(), 3u);
    for (double f : {373.0, 441.0, 409.0})
      EXPECT_TRUE(hasPeakNear(peaks, f, 1.0)) << "axis " << axis << " f " << f;
    std::printf("accel %c peaks: %.0f Hz %.0f Hz %.0f Hz\n", "xyz"[axis], peaks[0].frequency_hz,
                peaks[1].frequency_hz, peaks[2].frequency_hz);
  }
}

TEST(Dither, GyrosShowTheirDitherAndTheDifferenceFrequencies) {
  navbus::sim::DitherModel m({});
  const double f[3] = {373.0, 441.0, 409.0};
  for (int axis = 0; axis < 3; ++axis) {
    const auto x = series(m, true, axis, 1.0);
    const auto spectrum = navbus::core::amplitudeSpectrum(x, kRate);
    const auto high = navbus::core::largestPeaks(spectrum, kRate, x.size(), 300, 1200, 1);
    ASSERT_EQ(high.size(), 1u);
    EXPECT_NEAR(high[0].frequency_hz, f[axis], 1.0);
    const auto low = navbus::core::largestPeaks(spectrum, kRate, x.size(), 10, 100, 2);
    ASSERT_EQ(low.size(), 2u);
    for (int j = 0; j < 3; ++j) {
      if (j != axis) {
        EXPECT_TRUE(hasPeakNear(low, std::abs(f[axis] - f[j]), 1.0)) << "axis " << axis;
      }
    }
    std::printf("gyro %c: dither %.0f Hz, trapping %.0f Hz and %.0f Hz\n", "xyz"[axis],
                high[0].frequency_hz, low[0].frequency_hz, low[1].frequency_hz);
  }
}

TEST(Dither, PeakRateStaysWithinItsBoundsAndVaries) {
  navbus::sim::DitherModel m({});
  double lo = 1e9, hi = 0;
  for (int k = 0; k < 2000; ++k) {
    const double r = m.peakRate(0, k * 0.013);
    lo = std::min(lo, r);
    hi = std::max(hi, r);
  }
  EXPECT_GE(lo, 70.0 * M_PI / 180);
  EXPECT_LE(hi, 130.0 * M_PI / 180);
  EXPECT_GT(hi - lo, 50.0 * M_PI / 180);  // really random over the cycles
}
