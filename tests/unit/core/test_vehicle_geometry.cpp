// The vehicle's geometry in the measurement models: the antenna's lever arm in the GNSS
// position, velocity, pseudorange and pseudorange-rate rows (their H checked against finite
// differences of the measurement function) and the IMU's mounting rotation.
#include <gtest/gtest.h>

#include "navbus/core/filter/aiding_measurements.hpp"
#include "navbus/core/gnss/gnss_measurement.hpp"
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

/// A GPS satellite about 20,200 km above the vehicle's horizon, north-east and high, moving
/// at 3.9 km/s, whose measurements are those of an antenna at `antenna_ecef_m` moving at
/// `antenna_vel_ecef_mps` with no clock error.
core::SatelliteObservation satelliteSeenFrom(const Eigen::Vector3d& antenna_ecef_m,
                                             const Eigen::Vector3d& antenna_vel_ecef_mps,
                                             const earth::Geodetic& at) {
  const Eigen::Matrix3d C_n_e = earth::C_n_e(at.latitude_rad, at.longitude_rad);
  core::SatelliteObservation sat;
  sat.sv_id = 7;
  sat.sat_pos_ecef_m = antenna_ecef_m + C_n_e * Eigen::Vector3d(9.0e6, 6.0e6, -1.9e7);
  sat.sat_vel_ecef_mps = C_n_e * Eigen::Vector3d(-1200.0, 3500.0, 1100.0);
  const Eigen::Vector3d d = sat.sat_pos_ecef_m - antenna_ecef_m;
  sat.pseudorange_m = d.norm();
  sat.pseudorange_rate_mps = d.normalized().dot(sat.sat_vel_ecef_mps - antenna_vel_ecef_mps);
  return sat;
}

/// Central differences of a scalar z(state) over the position, velocity and attitude errors.
template <class Z>
Eigen::Matrix<double, 1, 9> numericRow(const core::NavState& truth, Z z) {
  Eigen::Matrix<double, 1, 9> h;
  for (int i = 0; i < 9; ++i) {
    // [m, m/s] and [rad]: large enough that rounding of the 23,000 km range (5e-9 m) stays
    // below 1e-5 of the derivative; the central difference's error is of third order.
    const double step = i < 6 ? 1e-2 : 1e-3;
    Eigen::Matrix<double, 9, 1> dx = Eigen::Matrix<double, 9, 1>::Zero();
    dx[i] = step;
    h[i] = (z(perturbed(truth, dx)) - z(perturbed(truth, -dx))) / (2 * step);
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

TEST(VehicleGeometry, PseudorangeRowsOfAnAntennaMatchFiniteDifferences) {
  // Given a vehicle turning with its antenna 1.9 m from the IMU, and a satellite whose
  // pseudorange and rate are those of the antenna,
  const core::NavState truth = vehicle();
  const core::AntennaArm arm{Eigen::Vector3d(1.2, -0.4, -1.5), Eigen::Vector3d(0.02, -0.05, 0.4)};
  const Eigen::Matrix3d C_n_e =
      earth::C_n_e(truth.position.latitude_rad, truth.position.longitude_rad);
  const Eigen::Vector3d antenna_ecef =
      earth::geodeticToEcef(truth.position) + C_n_e * (truth.q_b_to_n * arm.lever_arm_b_m);
  const Eigen::Vector3d antenna_vel_ecef =
      C_n_e * (truth.vel_ned_mps + truth.q_b_to_n * arm.rate_nb_b_radps.cross(arm.lever_arm_b_m));
  const core::SatelliteObservation sat =
      satelliteSeenFrom(antenna_ecef, antenna_vel_ecef, truth.position);
  const auto range = [&](const core::NavState& s) {
    return core::predictRange(s, 0.0, 0.0, sat, arm).pseudorange_m - sat.pseudorange_m;
  };
  const auto rate = [&](const core::NavState& s) {
    return core::predictRange(s, 0.0, 0.0, sat, arm).pseudorange_rate_mps -
           sat.pseudorange_rate_mps;
  };
  // then the innovations vanish at the truth (the prediction is of the antenna),
  EXPECT_LT(std::abs(range(truth)), 1e-6);
  EXPECT_LT(std::abs(rate(truth)), 1e-9);
  // and the rows match central differences of the prediction,
  const core::RangePrediction p = core::predictRange(truth, 0.0, 0.0, sat, arm);
  const Eigen::Matrix<double, 1, 9> numeric_range = numericRow(truth, range);
  EXPECT_LT((p.h_range.leftCols<9>() - numeric_range).cwiseAbs().maxCoeff(), 1e-5)
      << "analytic " << p.h_range.leftCols<9>() << "\nnumeric  " << numeric_range;
  const Eigen::Matrix<double, 1, 9> numeric_rate = numericRow(truth, rate);
  EXPECT_LT(
      (p.h_rate.block<1, 3>(0, layout::kVel.index) - numeric_rate.segment<3>(layout::kVel.index))
          .cwiseAbs()
          .maxCoeff(),
      1e-9);
  // The model neglects the rate's dependence on where the antenna is through the line of
  // sight (seed 000 eq. 5): |v_rel| / range per metre, 2e-4 /s here; times the arm on the
  // attitude columns.
  const double neglected_per_m =
      (sat.sat_vel_ecef_mps - antenna_vel_ecef).norm() / sat.pseudorange_m;
  EXPECT_LT(
      (p.h_rate.block<1, 3>(0, layout::kPos.index) - numeric_rate.segment<3>(layout::kPos.index))
          .cwiseAbs()
          .maxCoeff(),
      neglected_per_m);
  EXPECT_LT(
      (p.h_rate.block<1, 3>(0, layout::kAtt.index) - numeric_rate.segment<3>(layout::kAtt.index))
          .cwiseAbs()
          .maxCoeff(),
      neglected_per_m * arm.lever_arm_b_m.norm())
      << "analytic " << p.h_rate.leftCols<9>() << "\nnumeric  " << numeric_rate;
  // where the arm couples the attitude: a 10 mrad heading error moves a 1.3 m horizontal arm
  // by 13 mm and the antenna's 0.5 m/s about the IMU by 5 mm/s.
  EXPECT_GT((p.h_range.block<1, 3>(0, layout::kAtt.index).norm()), 0.3);
  EXPECT_GT((p.h_rate.block<1, 3>(0, layout::kAtt.index).norm()), 0.1);
}

TEST(VehicleGeometry, WithoutALeverArmThePseudorangeIsOfTheImu) {
  const core::NavState truth = vehicle();
  const Eigen::Vector3d imu_ecef = earth::geodeticToEcef(truth.position);
  const Eigen::Matrix3d C_n_e =
      earth::C_n_e(truth.position.latitude_rad, truth.position.longitude_rad);
  const core::SatelliteObservation sat =
      satelliteSeenFrom(imu_ecef, C_n_e * truth.vel_ned_mps, truth.position);
  const core::RangePrediction p = core::predictRange(truth, 0.0, 0.0, sat);
  EXPECT_NEAR(p.pseudorange_m, sat.pseudorange_m, 1e-6);
  EXPECT_NEAR(p.pseudorange_rate_mps, sat.pseudorange_rate_mps, 1e-9);
  EXPECT_TRUE((p.h_range.block<1, 3>(0, layout::kAtt.index).isZero()));
  EXPECT_TRUE((p.h_rate.block<1, 3>(0, layout::kAtt.index).isZero()));
}
