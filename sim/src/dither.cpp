#include "navbus/sim/dither.hpp"

#include <cmath>

namespace navbus::sim {

namespace {
/// A uniform number in [0, 1) from (seed, axis, knot): random access, so any sample can be
/// computed on its own and the stream is identical for the same seed (splitmix64 finalizer).
double uniform(std::uint64_t seed, int axis, std::int64_t cycle) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(axis + 1) +
                    0xBF58476D1CE4E5B9ULL * static_cast<std::uint64_t>(cycle);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}
}  // namespace

double DitherModel::peakRate(int axis, double t) const {
  const double x = t / spec_.amplitude_knot_s;
  const auto k = static_cast<std::int64_t>(std::floor(x));
  const double w = x - static_cast<double>(k);
  const double u = (1.0 - w) * uniform(spec_.seed, axis, k) + w * uniform(spec_.seed, axis, k + 1);
  return spec_.peak_rate_min_radps + (spec_.peak_rate_max_radps - spec_.peak_rate_min_radps) * u;
}

DitherSample DitherModel::at(double t) const {
  DitherSample d;
  Eigen::Vector3d s;  // sin(2 pi f_j t)
  for (int j = 0; j < 3; ++j) s[j] = std::sin(2.0 * M_PI * spec_.frequency_hz[j] * t);
  for (int i = 0; i < 3; ++i) {
    d.angular_rate_b_radps[i] = peakRate(i, t) * s[i];
    for (int j = 0; j < 3; ++j) {
      d.specific_force_b_mps2[i] +=
          (i == j ? spec_.accel_own_axis_mps2 : spec_.accel_cross_axis_mps2) * s[j];
      if (j != i) {
        const double df = std::abs(spec_.frequency_hz[i] - spec_.frequency_hz[j]);
        d.angular_rate_b_radps[i] += spec_.trapping_rate_radps * std::sin(2.0 * M_PI * df * t);
      }
    }
  }
  return d;
}

}  // namespace navbus::sim
