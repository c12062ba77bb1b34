// The vehicle's geometry in the measurement models: the antenna's lever arm in the GNSS
// position and velocity rows (their H checked against finite differences of the measurement
// function) and the IMU's mounting rotation.
#include <gtest/gtest.h>

#include "navbus/core/filter/aiding_measurements.hpp"
#include "navbus/core/ins/imu_mounting.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"

namespace core = navbus::core;
namespace earth = navbus::core::earth;
namespace layout = navbus::core::layout;
namespace units = navbus::units;

namespace {

core::NavState vehicle() {
  core::NavState s;
  s.time_ns = 1'400'000'000'000'000'000;
  s.position = {40.1 * units::kDeg, -105.15 * units::kDeg, 1580.0};
  s.vel_ned_mps = {9.0, -4.0, 0.3};
  s.q_b_to_n = Eigen::Quaterniond(core::dcmFromEuler({0.05, -0.12, 2.3}));
  return s;
}

/// The state with the error dx applied as the filter defines it: position and velocity
/// errors added (NED), attitude error phi with C_b_n,est = (I - [phi x]) C_b_n.
core::NavState perturbed(const core::NavState& truth, const Eigen::Matrix<double, 9, 1>& dx) {
  core::NavState s = truth;
  s.position = earth::offsetNed(truth.position, dx.segment<3>(layout::kPos.index));
  s.vel_ned_mps += dx.segment<3>(layout::kVel.index);
  const Eigen::Vector3d phi = dx.segment<3>(layout::kAtt.index);
  s.q_b_to_n = (core::quaternionFromRotationVector(-phi) * truth.q_b_to_n).normalized();
  return s;
}

/// Central differences of z(state) over the position, velocity and attitude errors.
template <class Z>
Eigen::Matrix<double, 3, 9> numericH(const core::NavState& truth, Z z) {
  Eigen::Matrix<double, 3, 9> h;
  for (int i = 0; i < 9; ++i) {
    const double step = i < 6 ? 1e-3 : 1e-6;  // [m, m/s] and [rad]
    Eigen::Matrix<double, 9, 1> dx = Eigen::Matrix<double, 9, 1>::Zero();
    dx[i] = step;
    h.col(i) = (z(perturbed(truth, dx)) - z(perturbed(truth, -dx))) / (2 * step);
  }
  return h;
}

}  // namespace

TEST(VehicleGeometry, AntennaPositionRowsMatchFiniteDifferences) {
  const core::NavState truth = vehicle();
  const Eigen::Vector3d lever_b(1.2, -0.4, -1.5);
  // The fix is where the antenna truly is: the innovation is zero at the truth.
  const earth::Geodetic antenna = earth::offsetNed(truth.position, truth.q_b_to_n * lever_b);
  const auto z = [&](const core::NavState& s) {
    return core::positionMeasurement(s, antenna, Eigen::Vector3d::Ones(), lever_b).z;
  };
  EXPECT_LT(z(truth).norm(), 1e-6);
  const auto m = core::positionMeasurement(truth, antenna, Eigen::Vector3d::Ones(), lever_b);
  const Eigen::Matrix<double, 3, 9> numeric = numericH(truth, z);
  EXPECT_LT((m.h.leftCols<9>() - numeric).cwiseAbs().maxCoeff(), 1e-5)
      << "analytic\n"
      << m.h.leftCols<9>() << "\nnumeric\n"
      << numeric;
  EXPECT_GT((m.h.block<3, 3>(0, layout::kAtt.index).norm()), 1.0) << "the arm couples attitude";
}

TEST(VehicleGeometry, AntennaVelocityRowsMatchFiniteDifferences) {
  const core::NavState truth = vehicle();
  const Eigen::Vector3d lever_b(1.2, -0.4, -1.5);
  const Eigen::Vector3d rate_b(0.02, -0.05, 0.4);  // a turn
  const Eigen::Vector3d antenna_vel = truth.vel_ned_mps + truth.q_b_to_n * rate_b.cross(lever_b);
  const auto z = [&](const core::NavState& s) {
    return core::velocityMeasurement(s, antenna_vel, Eigen::Vector3d::Ones(), lever_b, rate_b).z;
  };
  EXPECT_LT(z(truth).norm(), 1e-12);
  const auto m =
      core::velocityMeasurement(truth, antenna_vel, Eigen::Vector3d::Ones(), lever_b, rate_b);
  const Eigen::Matrix<double, 3, 9> numeric = numericH(truth, z);
  EXPECT_LT((m.h.leftCols<9>() - numeric).cwiseAbs().maxCoeff(), 1e-6)
      << "analytic\n"
      << m.h.leftCols<9>() << "\nnumeric\n"
      << numeric;
}

TEST(VehicleGeometry, WithoutALeverArmTheRowsAreThePointModels) {
  const core::NavState truth = vehicle();
  const auto p = core::positionMeasurement(truth, truth.position, Eigen::Vector3d::Ones());
  EXPECT_TRUE((p.h.block<3, 3>(0, layout::kAtt.index).isZero()));
  const auto v = core::velocityMeasurement(truth, truth.vel_ned_mps, Eigen::Vector3d::Ones());
  EXPECT_TRUE((v.h.block<3, 3>(0, layout::kAtt.index).isZero()));
}

TEST(VehicleGeometry, AnUpsideDownTurnedImuReadsInBodyAxes) {
  // The drive's published angles: at rest the IMU reads (0.118, 0.032, 1.006) g; in body axes
  // (forward, right, down) that is nearly (0, 0, -1) g: level, upside down, turned about z.
  const auto mounting =
      core::ImuMounting::fromRollPitchYaw(Eigen::Vector3d(180, -6.79, 185.35) * units::kDeg);
  core::ImuIncrement inc;
  inc.interval_s = 1.0;
  inc.delta_vel_b_mps = Eigen::Vector3d(0.118, 0.032, 1.006) * units::kStandardGravity;
  inc.delta_angle_b_rad = Eigen::Vector3d(0.0, 0.0, 0.1);
  const core::ImuIncrement body = mounting.toBody(inc);
  const Eigen::Vector3d f_g = body.delta_vel_b_mps / units::kStandardGravity;
  EXPECT_NEAR(f_g.x(), 0.0, 0.01);
  EXPECT_NEAR(f_g.y(), 0.0, 0.03);
  EXPECT_NEAR(f_g.z(), -1.01, 0.01);
  EXPECT_NEAR(body.delta_angle_b_rad.z(), -0.1 * std::cos(6.79 * units::kDeg), 1e-3)
      << "a turn about the IMU's z (up) is a turn about the body's down axis, reversed";
  EXPECT_NEAR(body.delta_vel_b_mps.norm(), inc.delta_vel_b_mps.norm(), 1e-12);
}
