// The IMU error model: its noise has the configured Allan characteristics, the deterministic
// errors have the configured sizes.
#include <cmath>

#include <gtest/gtest.h>

#include "navbus/core/math/allan.hpp"
#include "navbus/sim/imu_model.hpp"

using navbus::core::allanDeviation;
using navbus::sim::ImuErrorModel;
using navbus::sim::ImuSpec;
using navbus::sim::PerfectIncrement;

namespace {
/// Gyro-x rate output of `seconds` of a still sensor at 100 Hz.
std::vector<double> gyroRates(const ImuSpec& spec, double seconds, std::uint64_t seed) {
  ImuErrorModel model(spec, seed);
  const double dt = 0.01;
  std::vector<double> out;
  const auto n = static_cast<std::size_t>(seconds / dt);
  out.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    out.push_back(
        model.apply(PerfectIncrement{}, Eigen::Vector3d::Zero(), dt).delta_angle_b_rad.x() / dt);
  }
  return out;
}
}  // namespace

TEST(ImuModel, AllanDeviationRecoversTheAngleRandomWalk) {
  // Given ARW 0.005 deg/sqrt(h) (seed 001 tactical RLG), white noise only,
  ImuSpec spec;
  const double arw = 0.005 * M_PI / 180 / 60;  // rad/sqrt(s)
  spec.gyro.random_walk = arw;
  const auto rate = gyroRates(spec, 20000.0, 7);
  // then sigma_A(tau) = N / sqrt(tau) at tau = 1 s and 10 s, within 10 %.
  for (std::size_t m : {100u, 1000u}) {
    const double tau = 0.01 * static_cast<double>(m);
    const double measured = allanDeviation(rate, 0.01, m);
    const double expected = arw / std::sqrt(tau);
    std::printf("ARW check: tau %.0f s, Allan %.4e rad/s, expected %.4e (%.1f %%)\n", tau, measured,
                expected, 100 * (measured / expected - 1));
    EXPECT_NEAR(measured / expected, 1.0, 0.10);
  }
}

TEST(ImuModel, AllanDeviationRecoversTheBiasInstability) {
  // Given a bias instability of 0.01 deg/h modelled with a 100 s correlation time,
  ImuSpec spec;
  const double b = 0.01 * M_PI / 180 / 3600;
  spec.gyro.bias_instability = b;
  spec.gyro.bias_correlation_time_s = 100.0;
  const auto rate = gyroRates(spec, 100000.0, 9);
  // then the Allan deviation at its peak (1.89 correlation times) is the flicker floor 0.664 B.
  const auto m = static_cast<std::size_t>(navbus::sim::kGaussMarkovPeakTime * 100.0 / 0.01);
  const double measured = allanDeviation(rate, 0.01, m);
  const double expected = navbus::sim::kFlickerFloorFactor * b;
  std::printf("bias instability check: tau %.0f s, Allan %.4e rad/s, expected %.4e (%.1f %%)\n",
              0.01 * static_cast<double>(m), measured, expected, 100 * (measured / expected - 1));
  EXPECT_NEAR(measured / expected, 1.0, 0.10);
}

TEST(ImuModel, DeterministicErrorsHaveTheirConfiguredSize) {
  ImuSpec spec;
  spec.accel.bias = Eigen::Vector3d(1e-3, 0, 0);
  spec.accel.scale_factor = Eigen::Vector3d(0, 0, 100e-6);
  spec.accel.misalignment << 30e-6, 90e-6, -110e-6, 40e-6, 20e-6, -60e-6;
  spec.gyro_g_sensitivity(0, 2) = 1e-6;
  ImuErrorModel model(spec, 1);
  PerfectIncrement p;
  p.delta_vel_b_mps = Eigen::Vector3d(0, 0, -0.098);
  const auto out = model.apply(p, Eigen::Vector3d(0, 0, -9.8), 0.01);
  EXPECT_NEAR(out.delta_vel_b_mps.x(), 1e-3 * 0.01 + 90e-6 * -0.098, 1e-15);
  EXPECT_NEAR(out.delta_vel_b_mps.y(), 40e-6 * -0.098, 1e-15);
  EXPECT_NEAR(out.delta_vel_b_mps.z(), -0.098 * (1 + 100e-6), 1e-15);
  EXPECT_NEAR(out.delta_angle_b_rad.x(), 1e-6 * -9.8 * 0.01, 1e-15);
}

TEST(ImuModel, QuantizationCarriesItsRemainder) {
  ImuSpec spec;
  spec.gyro.quantum = 1e-6;
  ImuErrorModel model(spec, 1);
  PerfectIncrement p;
  p.delta_angle_b_rad = Eigen::Vector3d(0.3e-6, 0, 0);
  double sum = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const double q = model.apply(p, Eigen::Vector3d::Zero(), 0.01).delta_angle_b_rad.x();
    EXPECT_NEAR(std::remainder(q, 1e-6), 0.0, 1e-18);  // whole quanta
    sum += q;
  }
  EXPECT_NEAR(sum, 0.3e-3, 1e-6);  // no bias: within one quantum of the truth
}
