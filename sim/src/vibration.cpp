#include "navbus/sim/vibration.hpp"

#include <cmath>

namespace navbus::sim {

VehicleVibration::VehicleVibration(const VibrationSpec& spec, double sample_rate_hz,
                                   std::uint64_t seed)
    : spec_(spec), rng_(seed) {
  // Second-order Butterworth low-pass by the bilinear transform with pre-warping.
  const double k = std::tan(M_PI * spec.isolator_corner_hz / sample_rate_hz);
  const double q = 1.0 / std::sqrt(2.0);
  const double norm = 1.0 / (1.0 + k / q + k * k);
  b0_ = k * k * norm;
  b1_ = 2.0 * b0_;
  b2_ = b0_;
  a1_ = 2.0 * (k * k - 1.0) * norm;
  a2_ = (1.0 - k / q + k * k) * norm;
  // White input of variance s^2 per sample leaves the filter with variance s^2 times the
  // filter's noise gain sum h[n]^2, taken here from its impulse response.
  Biquad probe;
  double gain = 0.0;
  for (int n = 0; n < 100000; ++n) {
    const double h = filter(probe, n == 0 ? 1.0 : 0.0);
    gain += h * h;
  }
  input_sigma_accel_ = spec.accel_rms_mps2 / std::sqrt(gain);
  input_sigma_gyro_ = spec.gyro_rms_radps / std::sqrt(gain);
}

double VehicleVibration::filter(Biquad& s, double x) const {
  // Transposed direct form II.
  const double y = b0_ * x + s.z1;
  s.z1 = b1_ * x - a1_ * y + s.z2;
  s.z2 = b2_ * x - a2_ * y;
  return y;
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
