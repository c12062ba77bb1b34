#include "navbus/sim/vibration.hpp"

#include <cmath>

namespace navbus::sim {

VehicleVibration::Coefficients VehicleVibration::butterworth(double corner_hz, double rate_hz,
                                                             bool high_pass) {
  // Second-order Butterworth by the bilinear transform with pre-warping.
  const double k = std::tan(M_PI * corner_hz / rate_hz);
  const double q = 1.0 / std::sqrt(2.0);
  const double norm = 1.0 / (1.0 + k / q + k * k);
  Coefficients c;
  c.b0 = (high_pass ? 1.0 : k * k) * norm;
  c.b1 = (high_pass ? -2.0 : 2.0) * c.b0;
  c.b2 = c.b0;
  c.a1 = 2.0 * (k * k - 1.0) * norm;
  c.a2 = (1.0 - k / q + k * k) * norm;
  return c;
}

double VehicleVibration::step(const Coefficients& c, Biquad& s, double x) {
  // Transposed direct form II.
  const double y = c.b0 * x + s.z1;
  s.z1 = c.b1 * x - c.a1 * y + s.z2;
  s.z2 = c.b2 * x - c.a2 * y;
  return y;
}

double VehicleVibration::filter(std::array<Biquad, 2>& s, double x) const {
  return step(low_pass_, s[1], step(high_pass_, s[0], x));
}

VehicleVibration::VehicleVibration(const VibrationSpec& spec, double sample_rate_hz,
                                   std::uint64_t seed)
    : spec_(spec),
      low_pass_(butterworth(spec.isolator_corner_hz, sample_rate_hz, false)),
      high_pass_(butterworth(spec.low_corner_hz, sample_rate_hz, true)),
      rng_(seed) {
  // White input of variance s^2 per sample leaves the filter with variance s^2 times the
  // filter's noise gain sum h[n]^2, taken here from its impulse response.
  std::array<Biquad, 2> probe{};
  double gain = 0.0;
  for (int n = 0; n < 100000; ++n) {
    const double h = filter(probe, n == 0 ? 1.0 : 0.0);
    gain += h * h;
  }
  input_sigma_accel_ = spec.accel_rms_mps2 / std::sqrt(gain);
  input_sigma_gyro_ = spec.gyro_rms_radps / std::sqrt(gain);
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> VehicleVibration::next(double speed_mps) {
  const bool on = spec_.enabled && speed_mps > spec_.moving_speed_mps;
  Eigen::Vector3d f, w;
  for (int a = 0; a < 3; ++a) {
    const double xf = on ? input_sigma_accel_ * unit_(rng_) : 0.0;
    const double xw = on ? input_sigma_gyro_ * unit_(rng_) : 0.0;
    f[a] = filter(state_[static_cast<std::size_t>(a)], xf);
    w[a] = filter(state_[static_cast<std::size_t>(3 + a)], xw);
  }
  return {f, w};
}

}  // namespace navbus::sim
