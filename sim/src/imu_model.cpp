#include "navbus/sim/imu_model.hpp"

#include <cmath>

namespace navbus::sim {

namespace {
Eigen::Matrix3d scaleAndMisalignment(const TriadErrors& e) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m.diagonal() += e.scale_factor;
  const auto& a = e.misalignment;
  m(0, 1) = a[0];
  m(0, 2) = a[1];
  m(1, 0) = a[2];
  m(1, 2) = a[3];
  m(2, 0) = a[4];
  m(2, 1) = a[5];
  return m;
}
}  // namespace

ImuErrorModel::ImuErrorModel(const ImuSpec& spec, std::uint64_t seed)
    : spec_(spec),
      accel_sm_(scaleAndMisalignment(spec.accel)),
      gyro_sm_(scaleAndMisalignment(spec.gyro)),
      rng_(seed) {
  // Random-constant biases first, from this model's own stream: a new seed, new biases.
  for (int i = 0; i < 3; ++i) spec_.accel.bias[i] += spec.accel.random_constant_sigma * unit_(rng_);
  for (int i = 0; i < 3; ++i) spec_.gyro.bias[i] += spec.gyro.random_constant_sigma * unit_(rng_);
  // The bias-instability state starts in its stationary distribution.
  const double accel_s = kFlickerFloorFactor / kGaussMarkovPeakFactor * spec.accel.bias_instability;
  const double gyro_s = kFlickerFloorFactor / kGaussMarkovPeakFactor * spec.gyro.bias_instability;
  for (int i = 0; i < 3; ++i) {
    accel_gm_[i] = accel_s * unit_(rng_);
    gyro_gm_[i] = gyro_s * unit_(rng_);
  }
}

Eigen::Vector3d ImuErrorModel::triad(const TriadErrors& e, const Eigen::Matrix3d& sm,
                                     Eigen::Vector3d& gm, Eigen::Vector3d& residual,
                                     const Eigen::Vector3d& perfect,
                                     const Eigen::Vector3d& extra_rate, double dt) {
  // Bias instability as a first-order Gauss-Markov process whose Allan-deviation peak equals
  // the flicker floor 0.664 B of the datasheet value B.
  if (e.bias_instability > 0.0) {
    const double s = kFlickerFloorFactor / kGaussMarkovPeakFactor * e.bias_instability;
    const double phi = std::exp(-dt / e.bias_correlation_time_s);
    const double w = s * std::sqrt(1.0 - phi * phi);
    for (int i = 0; i < 3; ++i) gm[i] = phi * gm[i] + w * unit_(rng_);
  }
  Eigen::Vector3d out = sm * perfect + (e.bias + gm + extra_rate) * dt;
  // White rate noise of density N integrates to a random walk of sigma N sqrt(dt) per interval.
  if (e.random_walk > 0.0) {
    const double s = e.random_walk * std::sqrt(dt);
    for (int i = 0; i < 3; ++i) out[i] += s * unit_(rng_);
  }
  // Quantization with the remainder carried to the next interval: no bias, bounded error.
  if (e.quantum > 0.0) {
    const Eigen::Vector3d wanted = out + residual;
    for (int i = 0; i < 3; ++i) out[i] = std::round(wanted[i] / e.quantum) * e.quantum;
    residual = wanted - out;
  }
  return out;
}

PerfectIncrement ImuErrorModel::apply(const PerfectIncrement& perfect, const Eigen::Vector3d& f_b,
                                      double dt) {
  PerfectIncrement out;
  out.delta_vel_b_mps = triad(spec_.accel, accel_sm_, accel_gm_, accel_residual_,
                              perfect.delta_vel_b_mps, Eigen::Vector3d::Zero(), dt);
  out.delta_angle_b_rad = triad(spec_.gyro, gyro_sm_, gyro_gm_, gyro_residual_,
                                perfect.delta_angle_b_rad, spec_.gyro_g_sensitivity * f_b, dt);
  return out;
}

}  // namespace navbus::sim
