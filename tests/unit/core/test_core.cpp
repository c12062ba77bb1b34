// Core math: WGS84 model, rotations and the strapdown mechanization.
#include <cmath>

#include <gtest/gtest.h>

#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/sim/scenario_source.hpp"

namespace earth = navbus::core::earth;
using navbus::core::dcmFromEuler;
using navbus::core::eulerFromDcm;
using navbus::core::quaternionFromRotationVector;

TEST(Earth, NormalGravityMatchesWgs84ReferenceValues) {
  // TR8350.2 table values on the ellipsoid: equator and pole.
  EXPECT_NEAR(earth::normalGravity(0.0, 0.0), 9.7803253359, 1e-9);
  EXPECT_NEAR(earth::normalGravity(M_PI / 2, 0.0), 9.8321849378, 1e-9);
  // Free-air gradient about -3.086e-6 s^-2.
  const double dg = earth::normalGravity(0.6, 1000.0) - earth::normalGravity(0.6, 0.0);
  EXPECT_NEAR(dg, -3.086e-3, 1e-5);
}

TEST(Earth, GeodeticEcefRoundTripIsExactFromGroundToOrbit) {
  for (double lat : {-89.9, -45.0, 0.0, 36.5, 89.99}) {
    for (double lon : {-179.0, 0.0, 127.5}) {
      for (double h : {-100.0, 0.0, 10000.0, 500000.0, 20200000.0}) {
        const earth::Geodetic g{lat * M_PI / 180, lon * M_PI / 180, h};
        const earth::Geodetic back = earth::ecefToGeodetic(earth::geodeticToEcef(g));
        EXPECT_NEAR(back.latitude_rad, g.latitude_rad, 1e-11) << lat << " " << lon << " " << h;
        EXPECT_NEAR(back.longitude_rad, g.longitude_rad, 1e-11);
        EXPECT_NEAR(back.height_m, g.height_m, 1e-4);
      }
    }
  }
}

TEST(Earth, NedFrameIsOrthonormalAndDownPointsInward) {
  const Eigen::Matrix3d c = earth::C_n_e(0.7, 2.1);
  EXPECT_TRUE((c.transpose() * c).isApprox(Eigen::Matrix3d::Identity(), 1e-14));
  EXPECT_NEAR(c.determinant(), 1.0, 1e-14);
  const Eigen::Vector3d r = earth::geodeticToEcef({0.7, 2.1, 0.0});
  EXPECT_LT(r.normalized().dot(c.col(2)), -0.99);  // D column points towards the centre
}

TEST(Rotation, QuaternionFromRotationVectorMatchesAngleAxis) {
  for (const Eigen::Vector3d& phi :
       {Eigen::Vector3d(0.3, -0.2, 1.1), Eigen::Vector3d(1e-9, 2e-9, -1e-9),
        Eigen::Vector3d(0.0, 0.0, 0.0)}) {
    const Eigen::Quaterniond q = quaternionFromRotationVector(phi);
    const double angle = phi.norm();
    const Eigen::Matrix3d expected = angle > 0
                                         ? Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix()
                                         : Eigen::Matrix3d::Identity();
    EXPECT_TRUE(q.toRotationMatrix().isApprox(expected, 1e-14));
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
  }
}

// Below 1e-3 rad the rotation vector's quaternion comes from its Taylor series (no sine and
// cosine): the same as the closed form to rounding, up to the series' edge and just past it.
TEST(Rotation, TheSmallAngleSeriesEqualsTheClosedFormToRounding) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.48, -0.6, 0.64).normalized();
  for (double angle = 1e-7; angle < 2e-3; angle *= 1.3) {
    const Eigen::Quaterniond q = quaternionFromRotationVector(angle * axis);
    const Eigen::Quaterniond expected(Eigen::AngleAxisd(angle, axis));
    EXPECT_NEAR(q.w(), expected.w(), 2.3e-16) << angle;
    EXPECT_LT((q.vec() - expected.vec()).norm(), 4e-16 * angle) << angle;
  }
}

TEST(Rotation, EulerRoundTripAcrossAttitudes) {
  for (double r = -3.0; r <= 3.0; r += 1.5) {
    for (double p = -1.5; p <= 1.5; p += 0.5) {
      for (double y = -3.0; y <= 3.0; y += 1.0) {
        const Eigen::Vector3d rpy(r, p, y);
        EXPECT_TRUE(eulerFromDcm(dcmFromEuler(rpy)).isApprox(rpy, 1e-10)) << rpy.transpose();
      }
    }
  }
}

namespace {
/// Runs the mechanization on error-free stationary increments and returns the horizontal and
/// vertical position errors after `seconds`.
std::pair<double, double> stationaryDrift(double seconds, double yaw_deg) {
  navbus::sim::ScenarioConfig cfg;
  cfg.vehicle.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  cfg.vehicle.roll_pitch_yaw_rad = Eigen::Vector3d(0.02, -0.01, yaw_deg * M_PI / 180);
  cfg.gnss_every_n_increments = 0;
  cfg.star_tracker_every_n_increments = 0;
  cfg.raw_samples_per_increment = 1;
  navbus::sim::ScenarioSource source(cfg);
  navbus::core::StrapdownNed ins;
  navbus::core::NavState s0;
  s0.time_ns = cfg.start_time_ns;
  s0.position = cfg.vehicle.position;
  s0.q_b_to_n = Eigen::Quaterniond(dcmFromEuler(cfg.vehicle.roll_pitch_yaw_rad));
  ins.initialize(s0);
  const auto steps = static_cast<long>(seconds * 100);
  for (long k = 0; k < steps; ++k) ins.propagate(source.next().increment);
  const auto& p = ins.state().position;
  const earth::Radii radii = earth::radiiOfCurvature(p.latitude_rad);
  const double dn = (p.latitude_rad - cfg.vehicle.position.latitude_rad) * radii.meridian_m;
  const double de = (p.longitude_rad - cfg.vehicle.position.longitude_rad) *
                    radii.prime_vertical_m * std::cos(p.latitude_rad);
  return {std::hypot(dn, de), std::abs(p.height_m - cfg.vehicle.position.height_m)};
}
}  // namespace

TEST(Strapdown, ErrorFreeStationaryIncrementsKeepTheVehicleInPlace) {
  // Given exact increments of a vehicle at rest on the rotating Earth,
  // when they are integrated for 600 s (vertical channel unstable, so kept short),
  // then the position stays within centimetres for any heading.
  for (double yaw : {0.0, 45.0, 170.0}) {
    const auto [horizontal_m, vertical_m] = stationaryDrift(600.0, yaw);
    std::printf(
        "stationary error-free increments, 600 s, yaw %.0f deg: horizontal %.2e m, vertical %.2e "
        "m\n",
        yaw, horizontal_m, vertical_m);
    EXPECT_LT(horizontal_m, 0.01) << "yaw " << yaw;
    EXPECT_LT(vertical_m, 0.01) << "yaw " << yaw;
  }
}

TEST(Strapdown, UnmodelledAccelerometerBiasProducesTheSchulerDrift) {
  // A 100 ug north bias, no compensation: the classic first-order error after t seconds is
  // 0.5 * b * t^2 while t is much shorter than the Schuler period (84 min); check at 60 s.
  navbus::sim::ScenarioConfig cfg;
  cfg.vehicle.position = {0.5, 2.0, 0.0};
  cfg.gnss_every_n_increments = 0;
  cfg.star_tracker_every_n_increments = 0;
  cfg.raw_samples_per_increment = 1;
  cfg.imu.accel.bias = Eigen::Vector3d(100e-6 * 9.80665, 0, 0);
  navbus::sim::ScenarioSource source(cfg);
  navbus::core::StrapdownNed ins;
  navbus::core::NavState s0;
  s0.position = cfg.vehicle.position;
  ins.initialize(s0);
  for (int k = 0; k < 6000; ++k) ins.propagate(source.next().increment);
  const double dn = (ins.state().position.latitude_rad - cfg.vehicle.position.latitude_rad) *
                    earth::radiiOfCurvature(cfg.vehicle.position.latitude_rad).meridian_m;
  const double expected = 0.5 * 100e-6 * 9.80665 * 60.0 * 60.0;
  EXPECT_NEAR(dn, expected, 0.02 * expected);
}

TEST(Earth, NedOffsetAndDifferenceAreInverse) {
  const earth::Geodetic p{0.6, -2.9, 500.0};
  const Eigen::Vector3d d(120.0, -75.0, 30.0);
  const earth::Geodetic q = earth::offsetNed(p, d);
  // The two use the curvature at q and at p: they agree to second order, |d|^2 / R = 3 mm.
  EXPECT_LT((earth::differenceNed(q, p) - d).norm(), d.squaredNorm() / 6.3e6);
  // Against the exact ECEF geometry: the offset is the NED vector at p.
  const Eigen::Vector3d exact = earth::C_n_e(p.latitude_rad, p.longitude_rad).transpose() *
                                (earth::geodeticToEcef(q) - earth::geodeticToEcef(p));
  EXPECT_LT((exact - d).norm(), 0.01);
  EXPECT_NEAR(earth::differenceNed({0.0, M_PI - 1e-7, 0.0}, {0.0, -M_PI + 1e-7, 0.0}).y(),
              -2e-7 * 6378137.0, 1e-3);
}
