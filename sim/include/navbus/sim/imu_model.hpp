// IMU error model applied to perfect increments: constant bias, bias instability, white noise
// (angle and velocity random walk), scale factor, misalignment, g-dependent gyro error and
// quantization. SI units inside; ImuSpec::fromDatasheet converts the papers' table units once.
#pragma once

#include <cstdint>
#include <random>

#include <Eigen/Core>

#include "navbus/sim/trajectory.hpp"

namespace navbus::sim {

/// Errors of one sensor triad (accelerometers or gyros), SI.
struct TriadErrors {
  Eigen::Vector3d bias{Eigen::Vector3d::Zero()};  ///< constant (turn-on) bias [m/s^2 | rad/s]
  /// 1-sigma of a random-constant bias drawn per axis from the model's seed and added to `bias`
  /// (seeds 000, 004: a new value for every Monte Carlo seed) [m/s^2 | rad/s].
  double random_constant_sigma{0.0};
  double bias_instability{0.0};           ///< Allan floor B of the bias [m/s^2 | rad/s]
  double bias_correlation_time_s{100.0};  ///< Gauss-Markov correlation time modelling B
  double random_walk{0.0};                ///< white-noise density [m/s/sqrt(s) | rad/sqrt(s)]
  Eigen::Vector3d scale_factor{Eigen::Vector3d::Zero()};  ///< [-], e.g. 20e-6 for 20 ppm
  /// Axis misalignment [rad]: xy, xz, yx, yz, zx, zy; sensed_i = sum_j (I + M)_ij true_j.
  Eigen::Matrix<double, 6, 1> misalignment{Eigen::Matrix<double, 6, 1>::Zero()};
  double quantum{0.0};  ///< increment LSB [m/s | rad]; 0 = none
};

struct ImuSpec {
  TriadErrors accel;
  TriadErrors gyro;
  /// g-dependent gyro bias [rad/s per m/s^2]: gyro_i += G_ij f_j.
  Eigen::Matrix3d gyro_g_sensitivity{Eigen::Matrix3d::Zero()};
};

/// Allan-deviation floor of bias-instability (flicker) noise: 0.664 B (IEEE Std 952).
inline constexpr double kFlickerFloorFactor = 0.664;
/// Peak Allan deviation of a first-order Gauss-Markov process of standard deviation s is
/// 0.6174 s, reached at an averaging time of 1.89 correlation times.
inline constexpr double kGaussMarkovPeakFactor = 0.6174;
inline constexpr double kGaussMarkovPeakTime = 1.89;

class ImuErrorModel {
 public:
  ImuErrorModel(const ImuSpec& spec, std::uint64_t seed);

  /// Sensor output for one interval of length dt: the perfect increments with every error.
  /// `specific_force_b` drives the g-dependent gyro error.
  PerfectIncrement apply(const PerfectIncrement& perfect, const Eigen::Vector3d& specific_force_b,
                         double dt);

  /// Current total bias (constant + bias-instability state), for truth files.
  Eigen::Vector3d accelBias() const { return spec_.accel.bias + accel_gm_; }
  Eigen::Vector3d gyroBias() const { return spec_.gyro.bias + gyro_gm_; }

 private:
  Eigen::Vector3d triad(const TriadErrors& e, const Eigen::Matrix3d& sm, Eigen::Vector3d& gm,
                        Eigen::Vector3d& residual, const Eigen::Vector3d& perfect,
                        const Eigen::Vector3d& extra_rate, double dt);

  ImuSpec spec_;
  Eigen::Matrix3d accel_sm_;  ///< I + scale factor + misalignment
  Eigen::Matrix3d gyro_sm_;
  Eigen::Vector3d accel_gm_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d gyro_gm_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d accel_residual_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d gyro_residual_{Eigen::Vector3d::Zero()};
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_{0.0, 1.0};
};

}  // namespace navbus::sim
