// The IMU's scale-factor states (layout::kAccelScale, kGyroScale) in a closed loop: a car that
// turns both ways and speeds up and slows down, its IMU reading 0.5 % too much yaw rate and
// 0.3 % too much forward acceleration, fused with 4 Hz position and velocity fixes. The F
// columns themselves are checked against the nonlinear error growth in test_filter_core.cpp.
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "navbus/core/filter/aiding_measurements.hpp"
#include "navbus/core/filter/integrated_filter.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/sim/imu_model.hpp"
#include "navbus/sim/trajectory.hpp"

namespace {

namespace core = navbus::core;
namespace layout = core::layout;
using navbus::units::kDeg;

/// Laps of straight driving, a 180 deg turn at 15 deg/s one way, a speed change, and back.
std::vector<navbus::sim::Segment> scaleFactorLaps(int n) {
  std::vector<navbus::sim::Segment> segs;
  for (int i = 0; i < n; ++i) {
    const double turn = (i % 2 == 0 ? 1.0 : -1.0) * 15.0 * kDeg;
    navbus::sim::Segment straight, accelerate, turning, slow_down;
    straight.duration_s = 5.0;
    accelerate.duration_s = 4.0;
    accelerate.accel_mps2 = 1.5;
    turning.duration_s = 12.0;
    turning.heading_rate_radps = turning.yaw_rate_radps = turn;
    slow_down.duration_s = 4.0;
    slow_down.accel_mps2 = -1.5;
    segs.insert(segs.end(), {straight, accelerate, turning, slow_down});
  }
  return segs;
}

/// Runs the drive for `duration_s` with fixes every 0.25 s; the filter models scale factors
/// with `scale_sigma` (0: not modelled).
void runScaleFactorDrive(core::IntegratedFilter& f, double scale_sigma, double duration_s) {
  navbus::sim::VehicleStart start;
  start.position = {40.1 * kDeg, -105.1 * kDeg, 1580.0};
  start.speed_mps = 8.0;
  navbus::sim::VehicleTrajectory traj(start, scaleFactorLaps(20),
                                      core::earth::GravityModel::kWgs84Normal);
  navbus::sim::ImuSpec spec;
  spec.gyro.scale_factor = Eigen::Vector3d(0.0, 0.0, 5e-3);
  spec.accel.scale_factor = Eigen::Vector3d(3e-3, 0.0, 0.0);
  spec.gyro.random_walk = 0.1 * kDeg / 60.0;  // 0.1 deg/sqrt(h)
  spec.accel.random_walk = 1e-4;              // 100 (um/s^2)/sqrt(Hz)
  navbus::sim::ImuErrorModel imu(spec, 5);
  core::FilterTuning t;
  t.pos_sigma_m = 1.0;
  t.vel_sigma_mps = 0.1;
  t.accel_noise_mps2_per_sqrthz = 2e-4;
  t.gyro_noise_radps_per_sqrthz = 0.2 * kDeg / 60.0;
  t.accel_scale_sigma = scale_sigma;
  t.gyro_scale_sigma = scale_sigma;
  t.gate_sigma = 0.0;
  core::StateMask mask = core::maskOf(
      {layout::kPos, layout::kVel, layout::kAtt, layout::kAccelBias, layout::kGyroBias});
  if (scale_sigma > 0.0) mask |= core::maskOf({layout::kAccelScale, layout::kGyroScale});
  core::NavState s0 = traj.state();
  s0.time_ns = 0;
  f.initialize(s0, 0.0, 0.0, t, mask);
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n(0.0, 1.0);
  const double dt = 0.01;
  const auto steps = static_cast<int>(std::lround(duration_s / dt));
  for (int k = 1; k <= steps; ++k) {
    const navbus::sim::PerfectIncrement perfect = traj.advance(dt);
    const navbus::sim::PerfectIncrement sensed =
        imu.apply(perfect, perfect.delta_vel_b_mps / dt, dt);
    f.propagate({k * 10'000'000LL, dt, sensed.delta_vel_b_mps, sensed.delta_angle_b_rad});
    if (k % 25 != 0) continue;
    const core::NavState truth = traj.state();
    const Eigen::Vector3d pos_noise(0.05 * n(rng), 0.05 * n(rng), 0.05 * n(rng));
    const Eigen::Vector3d vel_noise(0.05 * n(rng), 0.05 * n(rng), 0.05 * n(rng));
    f.update(core::positionMeasurement(f.state(), core::earth::offsetNed(truth.position, pos_noise),
                                       Eigen::Vector3d::Constant(0.05)),
             core::AidingKind::kPosition);
    f.update(core::velocityMeasurement(f.state(), truth.vel_ned_mps + vel_noise,
                                       Eigen::Vector3d::Constant(0.05)),
             core::AidingKind::kVelocity);
  }
}

double scaleSigmaOf(const core::IntegratedFilter& f, int state) {
  return std::sqrt(f.covariance()(state, state));
}

TEST(ScaleFactors, TheFilterLearnsTheGyroAndAccelerometerScaleFactors) {
  // Given the drive (5 laps: ten 180 deg turns, twenty speed changes) and a prior of 1 %,
  core::IntegratedFilter f;
  runScaleFactorDrive(f, 1e-2, 125.0);
  const int gz = layout::kGyroScale.index + 2, ax = layout::kAccelScale.index;
  // then the yaw-rate scale factor is learnt to within 3 sigma with sigma under 0.05 %, and the
  // forward one to within 3 sigma with sigma under a third of the prior;
  EXPECT_NEAR(f.gyroScale().z(), 5e-3, 3.0 * scaleSigmaOf(f, gz));
  EXPECT_LT(scaleSigmaOf(f, gz), 5e-4);
  EXPECT_NEAR(f.accelScale().x(), 3e-3, 3.0 * scaleSigmaOf(f, ax));
  EXPECT_LT(scaleSigmaOf(f, ax), 1e-2 / 3.0);
  // and every other axis, whose truth is 0, stays within 3 sigma of it.
  for (int i = 0; i < 3; ++i) {
    if (i != 0) {
      EXPECT_LT(std::abs(f.accelScale()[i]), 3.0 * scaleSigmaOf(f, layout::kAccelScale.index + i))
          << "accelerometer axis " << i;
    }
    if (i != 2) {
      EXPECT_LT(std::abs(f.gyroScale()[i]), 3.0 * scaleSigmaOf(f, layout::kGyroScale.index + i))
          << "gyro axis " << i;
    }
  }
  std::printf("gyro z scale %.0f +- %.0f ppm (true 5000); accel x %.0f +- %.0f ppm (true 3000)\n",
              f.gyroScale().z() * 1e6, scaleSigmaOf(f, gz) * 1e6, f.accelScale().x() * 1e6,
              scaleSigmaOf(f, ax) * 1e6);
}

TEST(ScaleFactors, NotModelledTheyStayZeroAndKeepTheirVariance) {
  core::IntegratedFilter f;
  runScaleFactorDrive(f, 0.0, 30.0);
  EXPECT_EQ(f.gyroScale(), Eigen::Vector3d::Zero());
  EXPECT_EQ(f.accelScale(), Eigen::Vector3d::Zero());
  EXPECT_EQ(f.covariance()(layout::kGyroScale.index, layout::kGyroScale.index), 1.0);
}

}  // namespace
