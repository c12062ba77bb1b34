// The mounting calibration's arithmetic (evaluation/mounting_calibration.hpp): the residual
// from the velocity's direction in body axes, the straight-driving selection, and the
// corrected mounting angles.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "navbus/core/ins/imu_mounting.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/evaluation/mounting_calibration.hpp"

namespace navbus::evaluation {
namespace {

using units::kDeg;

/// An epoch of a vehicle driving along its own forward axis at `speed` on a road of `slope`
/// with `heading`, whose body axes are the vehicle's turned by `forward_in_body` (the
/// vehicle's forward axis in body axes is forward_in_body x).
core::SmoothedEpoch drivingEpoch(std::int64_t time_ns, double heading_rad, double slope_rad,
                                 double speed_mps, const Eigen::Matrix3d& forward_in_body) {
  const Eigen::Matrix3d C_v_n = core::dcmFromEuler(Eigen::Vector3d(0.0, slope_rad, heading_rad));
  core::SmoothedEpoch e;
  e.time_ns = time_ns;
  e.state.vel_ned_mps = C_v_n * Eigen::Vector3d(speed_mps, 0.0, 0.0);
  // Vehicle to body is forward_in_body, so body to NED is C_v_n forward_in_body^T.
  e.state.q_b_to_n = Eigen::Quaterniond(C_v_n * forward_in_body.transpose());
  e.smoothed = true;
  return e;
}

TEST(MountingCalibration, TheResidualIsTheVehiclesForwardAxisInBodyAxes) {
  // Given straight driving on headings and slopes that change between stretches, with the body
  // axes turned from the vehicle's by a pitch of 0.5 deg and a yaw of -1.2 deg, a slow stretch
  // and a turn with a sideslip of 5 deg, and an epoch the smoother did not reach,
  const Eigen::Matrix3d R = core::dcmFromEuler(Eigen::Vector3d(0.0, 0.5 * kDeg, -1.2 * kDeg));
  // (the turn's body axes are the same mounting plus a sideslip of 5 deg)
  const Eigen::Matrix3d sideslip = R * core::dcmFromEuler(Eigen::Vector3d(0.0, 0.0, 5.0 * kDeg));
  std::vector<core::SmoothedEpoch> epochs;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.1 * kDeg);
  std::int64_t t = 0;
  const std::int64_t step = 250'000'000;
  for (int stretch = 0; stretch < 4; ++stretch) {
    const double heading = stretch * 1.7, slope = (stretch - 1.5) * 2.0 * kDeg;
    for (int k = 0; k < 100; ++k) {
      const Eigen::Matrix3d jitter =
          core::dcmFromEuler(Eigen::Vector3d(0.0, noise(rng), noise(rng)));
      epochs.push_back(drivingEpoch(t += step, heading, slope, 12.0, jitter * R));
    }
  }
  for (int k = 0; k < 50; ++k)
    epochs.push_back(drivingEpoch(t += step, 0.3, 0.0, 2.0, sideslip));  // slow
  for (int k = 0; k < 50; ++k)                                           // turning at 10 deg/s
    epochs.push_back(drivingEpoch(t += step, 0.3 + (k + 1) * 2.5 * kDeg, 0.0, 12.0, sideslip));
  epochs.push_back(drivingEpoch(t += step, 0.3, 0.0, 12.0, sideslip));
  epochs.back().smoothed = false;
  // when calibrated with the defaults (above 5 m/s, below 2 deg/s),
  const MountingResidual r = mountingResidual(epochs, StraightDriving{});
  // then the straight epochs alone count (the first of each stretch turns from the last), and
  // the medians are the residual within the jitter's spread.
  EXPECT_EQ(r.epochs, 396u);
  EXPECT_NEAR(r.pitch_rad, 0.5 * kDeg, 0.02 * kDeg);
  EXPECT_NEAR(r.yaw_rad, -1.2 * kDeg, 0.02 * kDeg);
  EXPECT_LT(r.pitch_q1_rad, r.pitch_rad);
  EXPECT_GT(r.yaw_q3_rad, r.yaw_rad);
  // The constraint's rows over every fast epoch, the turn's too: in the configured axes they
  // carry 12 m/s times the residual (and the turn's sideslip); corrected, the sideslip and the
  // jitter (0.1 deg, 0.02 m/s) are left.
  EXPECT_EQ(r.moving_epochs, 450u);
  const auto rms = [](double straight_mps, double turn_mps) {
    return std::sqrt((400.0 * straight_mps * straight_mps + 50.0 * turn_mps * turn_mps) / 450.0);
  };
  EXPECT_NEAR(r.configured_rms_mps.x(),
              rms(12.0 * std::sin(1.2 * kDeg), 12.0 * std::sin(3.8 * kDeg)), 0.01);
  EXPECT_NEAR(r.corrected_rms_mps.x(), rms(0.0, 12.0 * std::sin(5.0 * kDeg)), 0.01);
  EXPECT_NEAR(r.configured_rms_mps.y(), 12.0 * std::sin(0.5 * kDeg), 0.01);
  EXPECT_LT(r.corrected_rms_mps.y(), 0.03);
}

TEST(MountingCalibration, TheVelocitysPitchFollowsTheLongitudinalAcceleration) {
  // Given straight driving whose speed swings between 10 and 14 m/s (accelerations up to
  // +-0.6 m/s^2), the body pitched against the track by -0.3 deg per m/s^2 plus a fixed 0.2 deg,
  const double k = -0.3 * kDeg;
  std::vector<core::SmoothedEpoch> epochs;
  for (int i = 0; i < 2000; ++i) {
    const double t = 0.1 * i;
    const double speed = 12.0 + 2.0 * std::sin(0.3 * t), accel = 0.6 * std::cos(0.3 * t);
    const Eigen::Matrix3d forward_in_body =
        core::dcmFromEuler(Eigen::Vector3d(0.0, 0.2 * kDeg + k * accel, 0.0));
    epochs.push_back(
        drivingEpoch(static_cast<std::int64_t>(i) * 100'000'000, 0.7, 0.0, speed, forward_in_body));
  }
  // when calibrated, then the slope is the configured one within 1 %, strongly correlated.
  const MountingResidual r = mountingResidual(epochs, StraightDriving{});
  EXPECT_NEAR(r.velocity_pitch_per_accel_rad_per_mps2, k, 0.01 * std::abs(k));
  EXPECT_LT(r.velocity_pitch_accel_correlation, -0.99);
  EXPECT_NEAR(r.pitch_rad, 0.2 * kDeg, 0.05 * kDeg);
}

TEST(MountingCalibration, TheCorrectedAnglesTurnTheForwardAxisOntoTheBodysX) {
  // Given the drive's published mounting (upside down, yawed 185 deg, pitched -6.79 deg) and a
  // residual of 0.4 deg pitch and 0.9 deg yaw,
  const auto before =
      core::ImuMounting::fromRollPitchYaw(Eigen::Vector3d(180.0, -6.79, 185.35) * kDeg);
  MountingResidual r;
  r.pitch_rad = 0.4 * kDeg;
  r.yaw_rad = 0.9 * kDeg;
  // when corrected,
  const auto after =
      core::ImuMounting::fromRollPitchYaw(correctedMountingRpy(before.sensor_to_body, r));
  // then the vehicle's forward axis, seen by the sensor, lands on the new body's x axis,
  const Eigen::Vector3d forward_b =
      core::dcmFromEuler(Eigen::Vector3d(0.0, r.pitch_rad, r.yaw_rad)) * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d forward_s = before.sensor_to_body.transpose() * forward_b;
  EXPECT_LT((after.sensor_to_body * forward_s - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  // and a zero residual gives the mounting back.
  const auto same =
      core::ImuMounting::fromRollPitchYaw(correctedMountingRpy(before.sensor_to_body, {}));
  EXPECT_LT((same.sensor_to_body - before.sensor_to_body).norm(), 1e-12);
}

}  // namespace
}  // namespace navbus::evaluation
