// Truth trajectories: integrating their perfect increments with the project's mechanization
// reproduces them.
#include <cmath>

#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/trajectory.hpp"
#include "test_paths.hpp"

namespace earth = navbus::core::earth;
using navbus::sim::Segment;

namespace {
constexpr double kDeg = M_PI / 180.0;

struct Errors {
  double position_m;
  double velocity_mps;
  double attitude_rad;
};

/// Mechanizes the trajectory's perfect increments at `rate_hz` for `seconds`; returns the final
/// errors against the truth.
Errors integrate(navbus::sim::Trajectory& truth, earth::GravityModel gravity, double rate_hz,
                 double seconds) {
  navbus::core::StrapdownNed ins(gravity);
  ins.initialize(truth.state());
  const double dt = 1.0 / rate_hz;
  const auto steps = static_cast<long>(std::llround(seconds * rate_hz));
  for (long k = 1; k <= steps; ++k) {
    const auto inc = truth.advance(dt);
    navbus::core::ImuIncrement m;
    m.time_ns = static_cast<std::int64_t>(std::llround(static_cast<double>(k) * dt * 1e9));
    m.interval_s = dt;
    m.delta_angle_b_rad = inc.delta_angle_b_rad;
    m.delta_vel_b_mps = inc.delta_vel_b_mps;
    ins.propagate(m);
  }
  const auto t = truth.state();
  const auto& s = ins.state();
  const Eigen::Vector3d dp = earth::geodeticToEcef(s.position) - earth::geodeticToEcef(t.position);
  const Eigen::AngleAxisd da(s.q_b_to_n * t.q_b_to_n.conjugate());
  return {dp.norm(), (s.vel_ned_mps - t.vel_ned_mps).norm(), std::abs(da.angle())};
}

navbus::sim::ScenarioConfig scenario(const std::string& file) {
  return navbus::sensor_sim::parseSimConfig(
             navbus::bus::loadYamlFile(std::string(navbus::test_paths::scenarioDir()) + "/" + file))
      .scenario;
}
}  // namespace

TEST(Trajectory, AircraftPerfectIncrementsReproduceTheTruthOver2000s) {
  // Given the seed-000 aircraft trajectory of the scenario file,
  const auto c = scenario("seed000_aircraft.yaml");
  navbus::sim::VehicleTrajectory truth(c.vehicle, c.segments, c.gravity);
  // when its perfect 100 Hz increments are integrated for 2000 s,
  const Errors e = integrate(truth, earth::GravityModel::kWgs84Normal, 100.0, 2000.0);
  std::printf("aircraft 2000 s: position error %.2e m, velocity %.2e m/s, attitude %.2e rad\n",
              e.position_m, e.velocity_mps, e.attitude_rad);
  // then the position error stays below 0.1 m (the target).
  EXPECT_LT(e.position_m, 0.1);
  EXPECT_LT(e.velocity_mps, 1e-3);
  EXPECT_LT(e.attitude_rad, 1e-6);
  EXPECT_NEAR(truth.state().vel_ned_mps.x(), 200.0, 1e-9);
}

TEST(Trajectory, ManoeuvresKeepIncrementsConsistent) {
  // Climb, coordinated-style turn with roll in and out, an attitude manoeuvre, acceleration.
  navbus::sim::VehicleStart start;
  start.position = {10.0 * kDeg, -60.0 * kDeg, 3000.0};
  start.speed_mps = 150.0;
  start.heading_rad = 45.0 * kDeg;
  start.roll_pitch_yaw_rad = Eigen::Vector3d(0.0, 0.0, 45.0 * kDeg);
  std::vector<Segment> segs;
  Segment climb{20.0};
  climb.climb_rate_radps = climb.pitch_rate_radps = 0.5 * kDeg;
  Segment level{20.0};
  level.climb_rate_radps = level.pitch_rate_radps = -0.5 * kDeg;
  Segment roll_in{3.0};
  roll_in.roll_rate_radps = 10.0 * kDeg;
  Segment turn{60.0};
  turn.heading_rate_radps = turn.yaw_rate_radps = 3.0 * kDeg;
  Segment roll_out{3.0};
  roll_out.roll_rate_radps = -10.0 * kDeg;
  Segment wiggle{10.0};
  wiggle.pitch_rate_radps = 2.0 * kDeg;
  Segment unwiggle{10.0};
  unwiggle.pitch_rate_radps = -2.0 * kDeg;
  Segment speed_up{30.0, 2.0};
  segs = {climb, level, roll_in, turn, roll_out, wiggle, unwiggle, speed_up};
  navbus::sim::VehicleTrajectory truth(start, segs, earth::GravityModel::kWgs84Normal);
  const Errors e = integrate(truth, earth::GravityModel::kWgs84Normal, 100.0, truth.duration());
  std::printf("manoeuvres %.0f s: position error %.2e m, velocity %.2e m/s, attitude %.2e rad\n",
              truth.duration(), e.position_m, e.velocity_mps, e.attitude_rad);
  EXPECT_LT(e.position_m, 0.05);
  EXPECT_LT(e.attitude_rad, 1e-6);
}

TEST(Trajectory, OrbitPeriodFollowsKeplerAndOneOrbitIsReproduced) {
  const auto c = scenario("seed001_leo.yaml");
  navbus::sim::OrbitStart o = c.orbit_start;
  o.start_gps_s = 1e-9 * static_cast<double>(c.start_time_ns);
  navbus::sim::CircularOrbitTrajectory truth(o);
  const double r = earth::kSemiMajorAxis_m + o.altitude_m;
  EXPECT_NEAR(truth.periodSeconds(), 2 * M_PI * std::sqrt(r * r * r / earth::kGm_m3ps2), 1e-9);
  EXPECT_NEAR(truth.periodSeconds(), 5677.0, 1.0);  // 500 km above a = 6378137 m: 94.6 min
  // Starts where it was asked to (geocentric latitude on the spherical Earth), at circular speed.
  const auto s0 = truth.state();
  const Eigen::Vector3d r0 = earth::geodeticToEcef(s0.position);
  EXPECT_NEAR(std::atan2(r0.z(), std::hypot(r0.x(), r0.y())), o.latitude_rad, 1e-9);
  EXPECT_NEAR(s0.position.longitude_rad, o.longitude_rad, 1e-9);
  EXPECT_NEAR(truth.velocityEci().norm(), std::sqrt(earth::kGm_m3ps2 / r), 1e-6);
  // One orbit of perfect 200 Hz increments through the NED mechanization with the same
  // (point-mass) gravity.
  const Errors e = integrate(truth, c.gravity, 200.0, truth.periodSeconds());
  std::printf("one orbit (%.0f s): position error %.2e m, velocity %.2e m/s, attitude %.2e rad\n",
              truth.periodSeconds(), e.position_m, e.velocity_mps, e.attitude_rad);
  EXPECT_LT(e.position_m, 1.0);
  const auto ri = truth.positionEci();
  EXPECT_NEAR(ri.norm(), r, 1e-6);
}
