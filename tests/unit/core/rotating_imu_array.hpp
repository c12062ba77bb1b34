// A rotating, accelerating rigid body sensed by an array of IMUs (three tilted units 0.4 m
// apart, each with its own constant biases and white noise), for the tests of the parity test
// (imu_array_parity.hpp) and of the least-squares combination (imu_array_combination.hpp).
#pragma once

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "navbus/core/ins/imu_array.hpp"
#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"

namespace navbus::test {

namespace nc = navbus::core;
namespace nu = navbus::units;

/// Room for six units' increments (ImuArrayParity::kMaxUnits, ImuArrayCombination::kMaxUnits).
using Increments = std::array<nc::ImuIncrement, 6>;

constexpr double kArrayDt = 0.01;  ///< [s] 100 Hz

inline std::vector<nc::ImuArrayUnit> triplexUnits() {
  const double gyro_sigma = 0.001 * nu::kDeg / 60.0 * std::sqrt(kArrayDt);  // 0.001 deg/sqrt(h)
  const double accel_sigma = 10.0 * nu::kMicroG * std::sqrt(kArrayDt);      // 10 ug/sqrt(Hz)
  std::vector<nc::ImuArrayUnit> units(3);
  const Eigen::Vector3d rpy_deg[3] = {{0, 0, 0}, {35, 0, 45}, {0, -35, -45}};
  const Eigen::Vector3d arm_m[3] = {{0, 0, 0}, {0.4, 0, 0}, {-0.4, 0, 0}};
  for (int u = 0; u < 3; ++u) {
    units[u].c_u_b = nc::dcmFromEuler(rpy_deg[u] * nu::kDeg).transpose();
    units[u].lever_arm_b_m = arm_m[u];
    units[u].gyro_sigma_rad = gyro_sigma;
    units[u].accel_sigma_mps = accel_sigma;
  }
  return units;
}

/// Increments of a rotating, accelerating rigid body sensed by the units: rates in their axes,
/// specific force at their place (first-order dw/dt, as the simulator), constant biases and
/// white noise; `step_mps2` added to unit `step_unit`'s accelerometer `step_axis`.
class RotatingBody {
 public:
  explicit RotatingBody(std::vector<nc::ImuArrayUnit> units) : units_(std::move(units)) {
    for (auto& b : gyro_bias_) b = Eigen::Vector3d::Random() * nu::kDegPerHour;
    for (auto& b : accel_bias_) b = Eigen::Vector3d::Random() * nu::kMilliG;
  }

  Increments next(int step_unit = -1, int step_axis = 0, double step_mps2 = 0.0) {
    const double t = kArrayDt * static_cast<double>(++k_);
    const Eigen::Vector3d w(0.3 * std::sin(t), 0.2 * std::cos(0.7 * t), 0.1 * std::sin(1.3 * t));
    const Eigen::Vector3d w_dot =
        k_ > 1 ? Eigen::Vector3d((w - w_prev_) / kArrayDt) : Eigen::Vector3d::Zero();
    w_prev_ = w;
    const Eigen::Vector3d f(0.5 * std::cos(0.2 * t), -0.2, -9.8);
    rate_b_ = w;
    specific_force_b_ = f;
    Increments out{};
    for (std::size_t u = 0; u < units_.size(); ++u) {
      const nc::ImuArrayUnit& unit = units_[u];
      const Eigen::Vector3d& r = unit.lever_arm_b_m;
      Eigen::Vector3d f_u = unit.c_u_b * (f + w_dot.cross(r) + w.cross(w.cross(r)));
      f_u += accel_bias_[u];
      if (static_cast<int>(u) == step_unit) f_u[step_axis] += step_mps2;
      out[u].time_ns = k_ * static_cast<long>(kArrayDt * 1e9);
      out[u].interval_s = kArrayDt;
      out[u].delta_angle_b_rad =
          (unit.c_u_b * w + gyro_bias_[u]) * kArrayDt + noise(unit.gyro_sigma_rad);
      out[u].delta_vel_b_mps = f_u * kArrayDt + noise(unit.accel_sigma_mps);
    }
    return out;
  }

  /// The body origin's rate [rad/s] and specific force [m/s^2] of the latest sample (body axes).
  const Eigen::Vector3d& rate_b() const { return rate_b_; }
  const Eigen::Vector3d& specificForce_b() const { return specific_force_b_; }
  /// Unit u's constant biases, in its own axes [rad/s, m/s^2].
  const Eigen::Vector3d& gyroBias(std::size_t u) const { return gyro_bias_[u]; }
  const Eigen::Vector3d& accelBias(std::size_t u) const { return accel_bias_[u]; }
  /// Noise off: the increments are the truth plus the biases.
  void noiseless() { noise_scale_ = 0.0; }

 private:
  Eigen::Vector3d noise(double sigma) {
    return Eigen::Vector3d(normal_(rng_), normal_(rng_), normal_(rng_)) * sigma * noise_scale_;
  }
  Eigen::Vector3d rate_b_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d specific_force_b_{Eigen::Vector3d::Zero()};
  double noise_scale_{1.0};
  std::vector<nc::ImuArrayUnit> units_;
  std::array<Eigen::Vector3d, 3> gyro_bias_, accel_bias_;
  Eigen::Vector3d w_prev_{Eigen::Vector3d::Zero()};
  long k_{0};
  std::mt19937_64 rng_{2026};
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace navbus::test
