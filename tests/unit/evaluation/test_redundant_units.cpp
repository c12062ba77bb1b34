// Further IMU units on the bus (imu_units): their increments go out under their own sensor ids
// in the same frames; a filter configured for one IMU refuses each as an unexpected source and
// counts it, and its solutions are bit for bit those of the same scenario without the units.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "navbus/bus/config.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/evaluation/offline_runner.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "test_paths.hpp"

namespace evaluation = navbus::evaluation;

namespace {

evaluation::OfflineResult run(const YAML::Node& scenario, double duration_s) {
  evaluation::OfflineSetup s;
  s.sim = navbus::sensor_sim::parseSimConfig(scenario);
  s.filter = navbus::nav_filter::parseFilterConfig(navbus::bus::loadYamlFile(
      std::string(navbus::test_paths::configDir()) + "/filter_seed000_tc.yaml"));
  s.filter.engine.initial_state = evaluation::initialTruth(s.sim.scenario);
  s.duration_s = duration_s;
  return evaluation::runOffline(s);
}

/// A triplex scenario `file` through the filter `filter` (in lanes) and the parity test of
/// config/fault_manager_triplex.yaml, keeping every lane's solutions.
evaluation::OfflineSetup triplexLanes(const std::string& file, const std::string& filter,
                                      double duration_s) {
  const std::string config = navbus::test_paths::configDir();
  evaluation::OfflineSetup s;
  s.sim = navbus::sensor_sim::parseSimConfig(
      navbus::bus::loadYamlFile(std::string(navbus::test_paths::scenarioDir()) + "/" + file));
  s.filter =
      navbus::nav_filter::parseFilterConfig(navbus::bus::loadYamlFile(config + "/" + filter));
  s.filter.engine.initial_state = evaluation::initialTruth(s.sim.scenario);
  s.fault_manager = navbus::fault_manager::parseFaultManagerConfig(
      navbus::bus::loadYamlFile(config + "/fault_manager_triplex.yaml"));
  s.duration_s = duration_s;
  s.keep_lane_solutions = true;
  return s;
}

}  // namespace

TEST(RedundantUnits, AOneImuFilterRefusesTheFurtherUnitsCountedAndUnchanged) {
  // Given the triplex scenario (sensor 1 and units 2 and 3, a gyro step on unit 2 at 502 s) and
  // the same scenario without the units, when each runs 600 s through the seed-000 filter (one
  // IMU, sensor 1), then the triplex run refuses 2 increments per frame as unexpected sources,
  // and both runs publish the same solutions bit for bit (the units' data never reach the
  // engine; unit 2's fault with them).
  const YAML::Node triplex = navbus::bus::loadYamlFile(
      std::string(navbus::test_paths::scenarioDir()) + "/seed000_triplex_gyro_step.yaml");
  ASSERT_EQ(navbus::sensor_sim::parseSimConfig(triplex).extra_imu_sensor_ids,
            (std::vector<std::uint32_t>{2, 3}));
  YAML::Node single = YAML::Clone(triplex);
  single.remove("imu_units");
  single.remove("faults");
  const evaluation::OfflineResult a = run(triplex, 600.0), b = run(single, 600.0);
  const auto refused = a.imu_rejected.find(navbus::REJECT_UNEXPECTED_SOURCE);
  ASSERT_NE(refused, a.imu_rejected.end()) << a.summary;
  EXPECT_EQ(refused->second, 2u * 60000u);
  EXPECT_TRUE(b.imu_rejected.empty());
  ASSERT_EQ(a.errors.size(), b.errors.size());
  ASSERT_GT(a.errors.size(), 500u);
  for (std::size_t i = 0; i < a.errors.size(); ++i) {
    ASSERT_EQ(a.errors[i].pos_ned_m, b.errors[i].pos_ned_m) << "solution " << i;
    ASSERT_EQ(a.errors[i].pos_sigma_ned_m, b.errors[i].pos_sigma_ned_m) << "solution " << i;
  }
}

namespace {

/// The triplex scenario `file` through the seed-000 filter and the triplex fault manager (its
/// parity test on the three units' increments), `duration_s` of it.
evaluation::OfflineResult runWithParity(const std::string& file, double duration_s) {
  const std::string dir = navbus::test_paths::scenarioDir();
  evaluation::OfflineSetup s;
  s.sim = navbus::sensor_sim::parseSimConfig(navbus::bus::loadYamlFile(dir + "/" + file));
  s.filter = navbus::nav_filter::parseFilterConfig(navbus::bus::loadYamlFile(
      std::string(navbus::test_paths::configDir()) + "/filter_seed000_tc.yaml"));
  s.filter.engine.initial_state = evaluation::initialTruth(s.sim.scenario);
  s.fault_manager = navbus::fault_manager::parseFaultManagerConfig(navbus::bus::loadYamlFile(
      std::string(navbus::test_paths::configDir()) + "/fault_manager_triplex.yaml"));
  s.duration_s = duration_s;
  return evaluation::runOffline(s);
}

double secondsIntoRun(std::uint64_t time_gps_ns) {
  return 1e-9 * static_cast<double>(time_gps_ns - 1400000000000000000ull);  // the scenario start
}

}  // namespace

TEST(RedundantUnits, TheParityTestIsolatesUnit2sGyroStepWithinFiveSeconds) {
  // Given the triplex scenario (a 10 deg/h x-gyro step on unit 2 at 502 s) and the fault
  // manager's parity test on the three units (config/fault_manager_triplex.yaml), when 520 s run
  // offline, then exactly one decision comes, from the parity test, after the onset and within
  // 5 s of it, naming unit 2's gyro x, not ambiguous, its size within 20 % of 10 deg/h; its
  // command fails that unit's axis, and the one-IMU filter (sensor 1) refuses it, naming why.
  const evaluation::OfflineResult r = runWithParity("seed000_triplex_gyro_step.yaml", 520.0);
  ASSERT_EQ(r.decisions.size(), 1u) << r.fault_summary;
  const navbus::FaultDecision& d = r.decisions[0];
  EXPECT_EQ(d.detector(), "parity");
  EXPECT_EQ(d.source(), navbus::SOURCE_GYRO);
  EXPECT_EQ(d.sensor_id(), 2u);
  EXPECT_EQ(d.axis(), 0);
  EXPECT_FALSE(d.ambiguous());
  EXPECT_GT(secondsIntoRun(d.time_gps_ns()), 502.0);
  EXPECT_LE(secondsIntoRun(d.time_gps_ns()), 507.0);
  EXPECT_NEAR(secondsIntoRun(d.onset_time_gps_ns()), 502.0, 0.2);
  EXPECT_NEAR(d.magnitude() / navbus::units::kDegPerHour, 10.0, 2.0);
  ASSERT_EQ(r.commands.size(), 1u);
  EXPECT_EQ(r.commands[0].kind(), navbus::CMD_FAIL_SENSOR_AXIS);
  EXPECT_EQ(r.commands[0].sensor_id(), 2u);
  EXPECT_NE(r.summary.find("commands applied 0 refused 1"), std::string::npos) << r.summary;
}

TEST(RedundantUnits, TheParityTestIsQuietOnAFaultFreeTriplexAndCatchesASlowRampEarly) {
  // Given the fault-free triplex aircraft, when its 2000 s run with the parity test, then no
  // decision comes and the largest statistic of either kind stays below the threshold. Given
  // the same with unit 1's x gyro ramping from 700 s at 0.0026 deg/h per second (3 minimum
  // detectable biases after 600 s), then the ramp is the one decision, unit 1 gyro x, before it
  // has reached three minimum detectable biases.
  const evaluation::OfflineResult quiet = runWithParity("seed000_triplex.yaml", 2000.0);
  EXPECT_TRUE(quiet.decisions.empty()) << quiet.fault_summary;
  EXPECT_NE(quiet.fault_summary.find("parity: 200000 aligned samples of 3 IMUs"), std::string::npos)
      << quiet.fault_summary;
  const evaluation::OfflineResult ramp = runWithParity("seed000_triplex_gyro_ramp.yaml", 2000.0);
  ASSERT_EQ(ramp.decisions.size(), 1u) << ramp.fault_summary;
  const navbus::FaultDecision& d = ramp.decisions[0];
  EXPECT_EQ(d.sensor_id(), 1u);
  EXPECT_EQ(d.source(), navbus::SOURCE_GYRO);
  EXPECT_EQ(d.axis(), 0);
  const double after_s = secondsIntoRun(d.time_gps_ns()) - 700.0;
  EXPECT_GT(after_s, 0.0);
  EXPECT_LT(after_s, 600.0);  // 3 x 0.52 deg/h at 0.0026 deg/h/s
  std::printf("ramp detected %.1f s after its start, at %.3f deg/h (3 x MDB = 1.56 deg/h)\n",
              after_s, 0.0026 * after_s);
}

TEST(RedundantUnits, LanesLeaveTheFailedUnitAndPublishTheJumpTheyMake) {
  // Given the triplex aircraft with unit 1's x gyro ramping from 700 s, the filter in three lanes
  // (config/filter_triplex.yaml) and the parity test, when 900 s run offline, then the parity
  // decision fails unit 1's axis, the selector leaves lane 1 for another at once (one switch,
  // counter 1), and the published solution at the switch is the new lane's: its reset deltas are
  // the new lane's solution minus lane 1's at the last time lane 1 was published, to 1 mm and
  // 1 mm/s (the published jump is that plus the new lane's motion over the step, to 1 mm), and
  // stay on every later solution with the counter; before the switch, lane 1 with zero deltas.
  const evaluation::OfflineSetup s =
      triplexLanes("seed000_triplex_gyro_ramp.yaml", "filter_triplex.yaml", 900.0);
  std::vector<navbus::NavigationSolution> published;
  const evaluation::OfflineResult r =
      evaluation::runOffline(s, [&](const navbus::NavigationSolution& sol, const auto&,
                                    const auto&) { published.push_back(sol); });
  ASSERT_EQ(r.decisions.size(), 1u) << r.fault_summary;
  EXPECT_EQ(r.decisions[0].sensor_id(), 1u);
  // Every solution is scored (from its message where the selected lane's engine had moved on).
  EXPECT_EQ(published.size(), r.solutions);
  EXPECT_LT(r.solutions_without_engine_state, 20u);
  ASSERT_EQ(r.lane_solutions.size(), 3 * r.solutions);
  std::size_t switch_at = published.size();
  for (std::size_t i = 0; i < published.size(); ++i) {
    if (published[i].lane_id() != 1u) {
      switch_at = i;
      break;
    }
    EXPECT_EQ(published[i].reset_count(), 0u);
    EXPECT_EQ(published[i].reset_delta_pos_ned_m()[0], 0.0);
  }
  ASSERT_LT(switch_at, published.size()) << "no switch";
  const navbus::NavigationSolution& after = published[switch_at];
  EXPECT_GE(after.time_gps_ns(), r.decisions[0].time_gps_ns());
  EXPECT_LE(after.time_gps_ns(), r.decisions[0].time_gps_ns() + 200'000'000ull);
  EXPECT_EQ(after.reset_count(), 1u);
  // The jump a consumer sees: from lane 1's last published solution to the new lane's. The
  // deltas are the two lanes' difference at that last time (lane 1 still as published), from
  // the lanes' stream.
  ASSERT_GT(switch_at, 0u);
  const std::uint64_t last_ns = published[switch_at - 1].time_gps_ns();
  const navbus::LaneSolution *old_lane = nullptr, *new_lane = nullptr, *old_now = nullptr;
  for (const navbus::LaneSolution& l : r.lane_solutions) {
    if (l.solution().time_gps_ns() == last_ns && l.lane_id() == 1u) old_lane = &l;
    if (l.solution().time_gps_ns() == last_ns && l.lane_id() == after.lane_id()) new_lane = &l;
    if (l.solution().time_gps_ns() == after.time_gps_ns() && l.lane_id() == 1u) old_now = &l;
  }
  ASSERT_NE(old_lane, nullptr);
  ASSERT_NE(new_lane, nullptr);
  ASSERT_NE(old_now, nullptr);
  EXPECT_FALSE(old_now->available());
  EXPECT_TRUE(old_lane->selected());
  const navbus::NavigationSolution& old = old_lane->solution();
  const navbus::NavigationSolution& now = new_lane->solution();
  const Eigen::Vector3d jump =
      navbus::core::earth::differenceNed({now.latitude_rad(), now.longitude_rad(), now.height_m()},
                                         {old.latitude_rad(), old.longitude_rad(), old.height_m()});
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(after.reset_delta_pos_ned_m()[i], jump[i], 1e-3);
    EXPECT_NEAR(after.reset_delta_vel_ned_mps()[i], now.vel_ned_mps()[i] - old.vel_ned_mps()[i],
                1e-3);
  }
  // The published jump is that difference plus the new lane's own motion over the step.
  const navbus::NavigationSolution& before = published[switch_at - 1];
  const Eigen::Vector3d seen = navbus::core::earth::differenceNed(
      {after.latitude_rad(), after.longitude_rad(), after.height_m()},
      {before.latitude_rad(), before.longitude_rad(), before.height_m()});
  const Eigen::Vector3d motion = navbus::core::earth::differenceNed(
      {after.latitude_rad(), after.longitude_rad(), after.height_m()},
      {now.latitude_rad(), now.longitude_rad(), now.height_m()});
  EXPECT_LT((seen - motion - jump).norm(), 1e-3);
  for (std::size_t i = switch_at; i < published.size(); ++i) {
    EXPECT_EQ(published[i].lane_id(), after.lane_id());
    EXPECT_EQ(published[i].reset_count(), 1u);
    EXPECT_EQ(published[i].reset_delta_pos_ned_m()[2], after.reset_delta_pos_ned_m()[2]);
  }
  // After the switch the published lane is another unit's: its biases are scored against that
  // unit's truth, turned into body axes, and its position at the unit's place (against unit 1's
  // biases the gyro-bias NEES was in the thousands).
  ASSERT_EQ(r.errors.size(), published.size());
  double accel_nees = 0.0, gyro_nees = 0.0;
  int scored = 0;
  for (std::size_t i = switch_at; i < r.errors.size(); ++i) {
    const auto& b = r.errors[i].nees_blocks;
    if (!std::isfinite(b[3]) || !std::isfinite(b[4])) continue;
    accel_nees += b[3];
    gyro_nees += b[4];
    ++scored;
  }
  ASSERT_GT(scored, 500);
  EXPECT_LT(accel_nees / scored, 15.0);  // 3 degrees of freedom: about 3 when consistent
  EXPECT_LT(gyro_nees / scored, 15.0);
  std::printf(
      "switch to lane %u at %.1f s; reset deltas position %.3f %.3f %.3f m; after it, "
      "mean bias NEES accelerometer %.2f gyro %.2f over %d solutions\n",
      after.lane_id(), secondsIntoRun(after.time_gps_ns()), jump[0], jump[1], jump[2],
      accel_nees / scored, gyro_nees / scored, scored);
}

namespace {

/// A dual-receiver scenario `file` (first `duration_s`) through the filter `filter` (the
/// seed-000 one by default) and config/fault_manager_dual_receivers.yaml.
evaluation::OfflineResult runDualReceivers(const std::string& file, double duration_s,
                                           const std::string& filter = "filter_seed000_tc.yaml") {
  evaluation::OfflineSetup s;
  s.sim = navbus::sensor_sim::parseSimConfig(
      navbus::bus::loadYamlFile(std::string(navbus::test_paths::scenarioDir()) + "/" + file));
  s.filter = navbus::nav_filter::parseFilterConfig(
      navbus::bus::loadYamlFile(std::string(navbus::test_paths::configDir()) + "/" + filter));
  s.filter.engine.initial_state = evaluation::initialTruth(s.sim.scenario);
  s.fault_manager = navbus::fault_manager::parseFaultManagerConfig(navbus::bus::loadYamlFile(
      std::string(navbus::test_paths::configDir()) + "/fault_manager_dual_receivers.yaml"));
  s.duration_s = duration_s;
  return evaluation::runOffline(s);
}

}  // namespace

TEST(RedundantReceivers, AClockJumpAndASpoofedSatelliteAreDecidedAtTheirFirstEpoch) {
  // Given the dual-receiver aircraft (receiver 2 beside the filter's receiver 1), when 720 s run
  // with the cross-receiver test: fault-free up to 700 s, nothing is decided, and the filter
  // refuses receiver 2's epochs as an unexpected source (one per epoch); when receiver 2's clock
  // jumps 1 ms at 700 s, the one decision names receiver 2's clock at 700 s with 299.79 km; when
  // satellite 13 of receiver 2 reads 100 m long from 700 s, the one decision names satellite 13
  // at 700 s, ambiguous between receivers 1 and 2, its difference about -100 m.
  const evaluation::OfflineResult jump =
      runDualReceivers("seed000_dual_receivers_clock_jump.yaml", 720.0);
  ASSERT_EQ(jump.decisions.size(), 1u) << jump.fault_summary;
  const navbus::FaultDecision& c = jump.decisions[0];
  EXPECT_EQ(c.source(), navbus::SOURCE_RECEIVER_CLOCK);
  EXPECT_EQ(c.sensor_id(), 2u);
  EXPECT_EQ(c.detector(), "receivers");
  EXPECT_NEAR(secondsIntoRun(c.time_gps_ns()), 700.0, 1e-6);
  EXPECT_NEAR(c.magnitude(), 299792.458, 50.0);
  const auto refused = jump.gnss_rejected.find(navbus::REJECT_UNEXPECTED_SOURCE);
  ASSERT_NE(refused, jump.gnss_rejected.end()) << jump.summary;
  EXPECT_EQ(refused->second, 720u);

  const evaluation::OfflineResult spoof =
      runDualReceivers("seed000_dual_receivers_spoofed.yaml", 720.0);
  ASSERT_EQ(spoof.decisions.size(), 1u) << spoof.fault_summary;
  const navbus::FaultDecision& s = spoof.decisions[0];
  EXPECT_EQ(s.source(), navbus::SOURCE_SATELLITE);
  EXPECT_EQ(s.sv_id(), 13u);
  EXPECT_TRUE(s.ambiguous());
  ASSERT_GE(s.candidates().size(), 2u);
  EXPECT_EQ(s.candidates()[0].sensor_id(), 1u);
  EXPECT_EQ(s.candidates()[1].sensor_id(), 2u);
  EXPECT_NEAR(secondsIntoRun(s.time_gps_ns()), 700.0, 1e-6);
  EXPECT_NEAR(s.magnitude(), -100.0, 20.0);
  EXPECT_NE(spoof.fault_summary.find("clock jumps 0, satellites decided 1"), std::string::npos)
      << spoof.fault_summary;
}

namespace {
/// Horizontal RMS error and mean NEES(9) of the solutions from `from_s` into the run.
std::pair<double, double> horizontalRmsAndNees(const evaluation::OfflineResult& r, double from_s) {
  double sum_h2 = 0.0, sum_nees = 0.0;
  int n = 0;
  for (const evaluation::EpochError& e : r.errors) {
    if (secondsIntoRun(static_cast<std::uint64_t>(e.time_ns)) < from_s) continue;
    sum_h2 += e.pos_ned_m.head<2>().squaredNorm();
    sum_nees += e.nees9;
    ++n;
  }
  return {std::sqrt(sum_h2 / std::max(n, 1)), sum_nees / std::max(n, 1)};
}
}  // namespace

TEST(RedundantReceivers, BothReceiversFusedMeasureBetterAndCloseTheLoopOnEither) {
  // Given the dual-receiver aircraft and config/filter_dual_receivers_fused.yaml (receiver 2's
  // pseudoranges stacked with receiver 1's, its own clock states and antenna), when 300 s run
  // fault-free, then receiver 2's epochs are taken (none refused), its clock is started once,
  // and the horizontal error after 100 s is below 0.8 of the one-receiver filter's on the same
  // data with NEES(9) in a consistent range (measured: 0.74 m against 1.20 m, NEES 7.4).
  const evaluation::OfflineResult one = runDualReceivers("seed000_dual_receivers.yaml", 300.0);
  const evaluation::OfflineResult both =
      runDualReceivers("seed000_dual_receivers.yaml", 300.0, "filter_dual_receivers_fused.yaml");
  EXPECT_EQ(both.gnss_rejected.count(navbus::REJECT_UNEXPECTED_SOURCE), 0u) << both.summary;
  EXPECT_NE(both.summary.find("further receivers' clocks started 1,"), std::string::npos)
      << both.summary;
  EXPECT_TRUE(both.decisions.empty()) << both.fault_summary;
  const auto [rms_one, nees_one] = horizontalRmsAndNees(one, 100.0);
  const auto [rms_both, nees_both] = horizontalRmsAndNees(both, 100.0);
  EXPECT_LT(rms_both, 0.8 * rms_one) << rms_both << " m against " << rms_one << " m";
  EXPECT_GT(nees_both, 3.0);
  EXPECT_LT(nees_both, 15.0);
  std::printf(
      "horizontal RMS after 100 s: %.3f m (both receivers) against %.3f m (receiver 1); "
      "NEES(9) %.2f against %.2f\n",
      rms_both, rms_one, nees_both, nees_one);

  // When receiver 2's clock jumps 1 ms at 700 s, its compensation is applied to receiver 2's
  // clock states (a one-receiver filter refuses it), and nothing else is decided.
  const evaluation::OfflineResult jump = runDualReceivers(
      "seed000_dual_receivers_clock_jump.yaml", 720.0, "filter_dual_receivers_fused.yaml");
  ASSERT_EQ(jump.decisions.size(), 1u) << jump.fault_summary;
  EXPECT_EQ(jump.decisions[0].sensor_id(), 2u);
  EXPECT_NE(jump.summary.find("commands applied 1 refused 0"), std::string::npos) << jump.summary;
  EXPECT_LT(horizontalRmsAndNees(jump, 690.0).first, 2.0);

  // When satellite 13 reads 30 m long at both receivers from 700 s (the receivers agree: the
  // cross-receiver test cannot see it), the GLR finds it in both receivers' rows of the
  // satellite at its first epoch.
  const evaluation::OfflineResult step = runDualReceivers(
      "seed000_dual_receivers_satellite_step.yaml", 720.0, "filter_dual_receivers_fused.yaml");
  ASSERT_EQ(step.decisions.size(), 1u) << step.fault_summary;
  EXPECT_EQ(step.decisions[0].source(), navbus::SOURCE_SATELLITE);
  EXPECT_EQ(step.decisions[0].sv_id(), 13u);
  EXPECT_EQ(step.decisions[0].detector(), "glr");
  EXPECT_NEAR(secondsIntoRun(step.decisions[0].time_gps_ns()), 700.0, 1e-6);
}

TEST(RedundantUnits, TheLeastSquaresLaneLeavesTheFailedInstrumentOutAndStaysHonest) {
  // Given the triplex aircraft with a 10 deg/h step on unit 2's x gyro at 502 s, the filter in
  // three lanes and a fourth on the least-squares combination of all nine gyros and nine
  // accelerometers, preferred (config/filter_triplex_least_squares.yaml), and the parity test,
  // when 700 s run offline, then the published solution is that lane's throughout (no switch),
  // the failed gyro leaves the combination at the decision, and the lane, scored against the
  // biases its combination carries (E b), is consistent after it: it re-learned the gyro bias
  // whose weights changed.
  const evaluation::OfflineSetup s =
      triplexLanes("seed000_triplex_gyro_step.yaml", "filter_triplex_least_squares.yaml", 700.0);
  std::vector<navbus::NavigationSolution> published;
  const evaluation::OfflineResult r =
      evaluation::runOffline(s, [&](const navbus::NavigationSolution& sol, const auto&,
                                    const auto&) { published.push_back(sol); });
  ASSERT_EQ(r.decisions.size(), 1u) << r.fault_summary;
  EXPECT_EQ(r.decisions[0].sensor_id(), 2u);
  EXPECT_EQ(r.lane_solutions.size(), 4 * r.solutions);
  for (const navbus::NavigationSolution& sol : published) {
    ASSERT_EQ(sol.lane_id(), 9u) << secondsIntoRun(sol.time_gps_ns());
    ASSERT_EQ(sol.reset_count(), 0u);
  }
  EXPECT_NE(r.summary.find("instruments taken out 1"), std::string::npos) << r.summary;
  double gyro_nees = 0.0, nees9 = 0.0;
  int scored = 0;
  for (std::size_t i = 0; i < r.errors.size(); ++i) {
    if (published[i].time_gps_ns() < r.decisions[0].time_gps_ns()) continue;
    const auto& b = r.errors[i].nees_blocks;
    if (!std::isfinite(b[4]) || !std::isfinite(r.errors[i].nees9)) continue;
    gyro_nees += b[4];
    nees9 += r.errors[i].nees9;
    ++scored;
  }
  ASSERT_GT(scored, 1500);
  EXPECT_LT(gyro_nees / scored, 9.0);  // 3 degrees of freedom: about 3 when consistent
  EXPECT_LT(nees9 / scored, 20.0);     // 9 degrees of freedom
  std::printf(
      "least-squares lane after the decision at %.1f s: mean NEES(9) %.2f, gyro-bias NEES %.2f "
      "over %d solutions\n",
      secondsIntoRun(r.decisions[0].time_gps_ns()), nees9 / scored, gyro_nees / scored, scored);
}

TEST(RedundantUnits, TheLeastSquaresLaneGoesThroughTheAlignmentBeforeTheFirstJudgement) {
  // Given the fault-free triplex and the least-squares lane, the filter aligning from its inputs
  // (the fault manager's first report comes with its first diagnostics, after the alignment),
  // when 100 s run offline, then the combination does not wait for that report beyond the
  // judgement's wait: its lane integrates every increment the units' lanes do (none refused as
  // late: before, 8300 of 10000 were) and publishes as many solutions; the waits are counted.
  evaluation::OfflineSetup s =
      triplexLanes("seed000_triplex.yaml", "filter_triplex_least_squares.yaml", 100.0);
  s.filter.engine.start = navbus::core::StartSource::kAligned;
  const evaluation::OfflineResult r = evaluation::runOffline(s);
  EXPECT_GT(r.solutions, 300u);
  std::size_t lane9 = 0, lane1 = 0;
  for (const navbus::LaneSolution& l : r.lane_solutions) {
    lane9 += l.lane_id() == 9u ? 1 : 0;
    lane1 += l.lane_id() == 1u ? 1 : 0;
  }
  EXPECT_EQ(lane9, lane1);
  EXPECT_EQ(r.summary.find("rejected"), std::string::npos) << r.summary;
  EXPECT_NE(r.summary.find("lane IMU 9: increments integrated 3801"), std::string::npos)
      << r.summary;
  EXPECT_NE(r.summary.find("combined beyond the parity test's judgement (its wait ran out) "),
            std::string::npos)
      << r.summary;
}
