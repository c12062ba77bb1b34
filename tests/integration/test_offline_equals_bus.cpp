// The offline runner (`navbus offline`, no DDS) and the three participants over the bus give
// bit-identical solutions for the same scenario, seed and filter configuration
// (docs/architecture.md, the ordered merge). Two scenarios: the seed-004 land vehicle with the
// multi-dimensional filter (ZUPT, NHC, stage switches, resets) and 40 s of the seed-001 LEO with
// GNSS fixes and the star tracker in the federated structure.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/HealthPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "harness.hpp"
#include "navbus/records/formatters.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace std::chrono_literals;

namespace {

struct Case {
  int domain;
  std::string scenario;  ///< file under sim/scenarios
  std::string filter;    ///< file under config
  std::string filter_extra;
  int seed;
  double duration_s;
  std::vector<std::string> filter_log_says{};  ///< lines the filter's log must contain
  std::string
      fault_manager{};       ///< file under config for both runs ("": the defaults, offline none)
  std::size_t decisions{0};  ///< with fault_manager: the decisions both runs must publish
  std::string sim_extra{};   ///< YAML appended to the scenario (e.g. its faults)
  /// The sensors the filter's last health report must count on a topic, each under its id:
  /// "topic id:accepted id:refused ..." (accepted: samples accepted, none rejected; refused:
  /// every sample rejected).
  std::string filter_sensors{};
  std::string fm_sensors{};  ///< the same for the fault manager's last health report
  /// The simulator paces its data in real time (as a receiver's epochs come): each of them
  /// reaches the filter and the fault manager together, and the filter has gone on to its time
  /// before the fault manager could judge it (default: as fast as the readers take it).
  bool realtime{false};
  /// The watchdog's decisions are wall-time judgements of the bus run (a stream silent for
  /// seconds; also, at times, a stream's end that its best-effort reader missed): left out of
  /// the comparison. Those about this receiver's epochs (0: none checked) must be this many.
  std::uint32_t watched_receiver{0};
  std::size_t watchdog_decisions{0};
  std::vector<std::string> fm_log_lacks{};  ///< lines the fault manager's log must not contain
};

/// Checks `expected` (Case::filter_sensors) against the input of a health report.
void expectSensorCounts(const Health& health, const std::string& expected) {
  std::istringstream words(expected);
  std::string topic, item;
  words >> topic;
  const StreamHealth* in = nullptr;
  for (const auto& i : health.inputs())
    if (i.topic().to_string() == topic) in = &i;
  ASSERT_NE(in, nullptr) << topic << " not among the inputs of " << health.participant();
  std::vector<std::string> seen;
  for (const SensorStreamHealth& s : in->sensors())
    seen.push_back(std::to_string(s.sensor_id()) +
                   (s.rejected() == 0 && s.accepted() > 0   ? ":accepted"
                    : s.accepted() == 0 && s.rejected() > 0 ? ":refused"
                                                            : ":mixed"));
  std::vector<std::string> wanted;
  while (words >> item) wanted.push_back(item);
  EXPECT_EQ(seen, wanted) << topic;
  EXPECT_EQ(in->unlisted_sensor_samples(), 0u);
  std::uint64_t accepted = 0;
  for (const SensorStreamHealth& s : in->sensors()) accepted += s.accepted();
  EXPECT_EQ(accepted, in->accepted()) << "the ids' counts add up to the topic's";
}

/// A decision as CSV, without its run_id (the last column: the bus run's start time, 0 offline)
/// and its decision_id (the first: on the bus the watchdog's wall-time decisions, left out of
/// the comparison, take ids between the others; measured: the lanes' decision came as 4 instead
/// of 2 after two end-of-data LOSTs, 1 run in 14).
std::string withoutIds(const std::string& row) {
  const std::size_t first = row.find(',') + 1;
  return row.substr(first, row.rfind(',') - first);
}

void runCase(const Case& c) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("offline-" + std::to_string(c.domain));
  const std::string scenario = std::string(navbus::test_paths::scenarioDir()) + "/" + c.scenario;
  const std::string filter_base = std::string(navbus::test_paths::configDir()) + "/" + c.filter;
  const std::string domain = "domain_id: " + std::to_string(c.domain) + "\n";
  const std::string sim_cfg = test::writeFile(
      dir / "sim.yaml", "extends: " + scenario + "\n" + domain +
                            "timing: {duration_s: " + std::to_string(c.duration_s) +
                            (c.realtime ? ", pacing: realtime" : "") + "}\n" + c.sim_extra);
  // Every solution must reach the test even though the data runs through at full speed. The
  // sequencer's bounded wait is the one place where wall time enters the bus run (a stream
  // silent for longer is set aside, which the offline run never does); on a loaded machine or
  // under the sanitizers a first sample has lagged its neighbours by more than 5 s, so this
  // comparison waits up to 30 s. The end of the data costs no wait: the simulator disposes its
  // streams and the filter stops waiting for them. The other place is the fault monitor's
  // liveness (its health every second, 3 s allowed): under the sanitizers the fault manager's
  // reports once came more than 3 s apart at the end of the run, and the last 15 of 400 bus
  // solutions carried FAULT_NO_FAULT_MONITOR; 30 s here too (test_kill_loop tests liveness).
  const std::string filter_cfg = test::writeFile(
      dir / "filter.yaml",
      "extends: " + filter_base + "\n" + domain +
          "solution_writer_profile: navbus_solution_writer_lossless\n" +
          "sequencer_max_wait_s: 30\n" +
          "fault_monitor: {participant: navbus-fault-manager, timeout_s: 30}\n" + c.filter_extra);
  const std::string fm_cfg = test::writeFile(
      dir / "fm.yaml",
      (c.fault_manager.empty() ? std::string()
                               : "extends: " + std::string(navbus::test_paths::configDir()) + "/" +
                                     c.fault_manager + "\n") +
          domain);

  // Offline first: no DDS at all.
  std::vector<std::string> offline_args = {"offline",
                                           "--scenario",
                                           sim_cfg,
                                           "--filter",
                                           filter_cfg,
                                           "--start",
                                           "config",
                                           "--seed",
                                           std::to_string(c.seed),
                                           "-o",
                                           (dir / "offline").string()};
  if (!c.fault_manager.empty()) {
    offline_args.push_back("--fault-manager");
    offline_args.push_back(fm_cfg);
  }
  test::ChildProcess offline(navbus::test_paths::toolExe(), offline_args,
                             (dir / "offline.log").string());
  ASSERT_EQ(offline.wait(120s), 0) << test::readFile(dir / "offline.log");
  const std::vector<std::string> expected = test::csvDataRows(dir / "offline" / "solution.csv");
  ASSERT_GT(expected.size(), 100u);
  std::vector<std::string> expected_decisions;
  if (!c.fault_manager.empty())
    for (const std::string& row : test::csvDataRows(dir / "offline" / "decisions.csv"))
      expected_decisions.push_back(withoutIds(row));

  // The same over the bus: simulator, filter and fault manager as separate processes.
  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(c.domain, "offline-equals-bus"), shutdown);
  std::vector<std::string> rows;
  std::size_t flagged_gnss_lost = 0;
  me.subscribe<NavigationSolutionPubSubType>(bus::topic::kNavSolution,
                                             bus::profile::kSolutionReader,
                                             [&](const NavigationSolution& s, const auto&) {
                                               if (s.mode() != MODE_INERTIAL_LOST)
                                                 rows.push_back(records::csvRows(s).at(0));
                                               if (s.active_fault_flags() & FAULT_GNSS_STREAM_LOST)
                                                 ++flagged_gnss_lost;
                                             });
  std::vector<std::string> decisions;
  std::size_t watchdog_decisions = 0;
  me.subscribe<FaultDecisionPubSubType>(
      bus::topic::kFaultDecision, bus::profile::kDecisionReader,
      [&](const FaultDecision& d, const auto&) {
        if (d.detector() == "watchdog") {
          if (d.source() == SOURCE_GNSS_OBS_STREAM && d.sensor_id() == c.watched_receiver)
            ++watchdog_decisions;
          return;
        }
        decisions.push_back(withoutIds(records::csvRows(d).at(0)));
      });
  Health filter_health, fm_health;
  me.subscribe<HealthPubSubType>(bus::topic::kHealth, bus::profile::kHealthReader,
                                 [&](const Health& h, const auto&) {
                                   const std::string who = h.participant().to_string();
                                   if (who == "navbus-filter") filter_health = h;
                                   if (who == "navbus-fault-manager") fm_health = h;
                                 });
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  test::ChildProcess fm(navbus::test_paths::faultManagerExe(), {"-c", fm_cfg},
                        (dir / "fm.log").string());
  test::ChildProcess sim(navbus::test_paths::sensorSimExe(),
                         {"-c", sim_cfg, "--seed", std::to_string(c.seed)},
                         (dir / "sim.log").string());
  // The simulator waits for the filter and the fault manager, publishes as fast as they take
  // it (reliable, nothing lost) and exits.
  while (sim.running()) me.spinOnce(50ms);
  EXPECT_EQ(sim.wait(1s), 0) << test::readFile(dir / "sim.log");
  test::spinUntil(me, 60s, [&] { return rows.size() >= expected.size(); });
  me.spinOnce(500ms);  // anything more that would arrive
  filter.signal(SIGTERM);
  fm.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  EXPECT_EQ(fm.wait(10s), 0);
  test::spinUntil(me, 5s, [&] {
    return filter_health.state() == STATE_STOPPING && fm_health.state() == STATE_STOPPING;
  });
  if (!c.filter_sensors.empty()) {
    ASSERT_EQ(filter_health.state(), STATE_STOPPING) << "the filter's last health report";
    expectSensorCounts(filter_health, c.filter_sensors);
  }
  if (!c.fm_sensors.empty()) {
    ASSERT_EQ(fm_health.state(), STATE_STOPPING) << "the fault manager's last health report";
    expectSensorCounts(fm_health, c.fm_sensors);
  }

  ASSERT_EQ(rows.size(), expected.size()) << test::readFile(dir / "filter.log");
  const std::size_t differing = test::countDiffering(rows, expected);
  EXPECT_EQ(differing, 0u);
  std::printf("%s: %zu solutions, bus and offline bit-identical (17-digit CSV rows): %s\n",
              c.scenario.c_str(), rows.size(), differing == 0 ? "yes" : "NO");
  EXPECT_EQ(flagged_gnss_lost, 0u) << "solutions flagged FAULT_GNSS_STREAM_LOST";
  // The last solutions came without a bounded wait: the announced end released them.
  const std::string log = test::readFile(dir / "filter.log");
  EXPECT_NE(log.find("navbus/imu/increment id 1 ended (its writer disposed it)"), std::string::npos)
      << log;
  EXPECT_NE(log.find("sequencer timeouts 0,"), std::string::npos) << log;
  for (const std::string& line : c.filter_log_says)
    EXPECT_NE(log.find(line), std::string::npos) << line;
  const std::string fm_log = test::readFile(dir / "fm.log");
  for (const std::string& line : c.fm_log_lacks)
    EXPECT_EQ(fm_log.find(line), std::string::npos) << line << "\n" << fm_log;
  if (!c.fault_manager.empty()) {
    // The fault manager's decisions (the parity test's on the units' increments, taken from
    // the bus in whatever order the units' samples arrive) are the offline run's, field for field.
    EXPECT_EQ(expected_decisions.size(), c.decisions) << test::readFile(dir / "offline.log");
    EXPECT_EQ(decisions, expected_decisions) << test::readFile(dir / "fm.log");
    EXPECT_EQ(watchdog_decisions, c.watchdog_decisions) << test::readFile(dir / "fm.log");
    std::printf("%zu decisions, bus and offline identical: %s\n", decisions.size(),
                decisions == expected_decisions ? "yes" : "NO");
  }
  test::cleanSharedMemory();
  // A failed run keeps its logs for the reader (the path is in the test's output).
  if (::testing::Test::HasFailure())
    std::printf("logs kept in %s\n", dir.c_str());
  else
    std::filesystem::remove_all(dir);
}

}  // namespace

TEST(OfflineEqualsBus, LandVehicleMultiDimensionalFilter) {
  runCase({86, "seed004_land_vehicle.yaml", "filter_seed004_mdf.yaml", "", 5, 160.0});
}

TEST(OfflineEqualsBus, LeoFederatedGnssAndStarTracker) {
  runCase({87, "seed001_leo.yaml", "filter_seed001_lc.yaml", "fusion: federated\n", 3, 40.0});
}

// A triplex installation (sensor 1 and units 2 and 3) into a filter configured for sensor 1: the
// units' increments go over the bus in blocks of their own instances, the filter refuses them
// as unexpected sources, and its solutions stay those of the offline run. The fault manager's
// parity test reads all three units and isolates unit 2's gyro step at 502 s: the same decision
// as offline (its command is refused by the one-IMU filter, which has no unit 2).
TEST(OfflineEqualsBus, TriplexUnitsBesideAOneImuFilter) {
  runCase({92,
           "seed000_triplex_gyro_step.yaml",
           "filter_seed000_tc.yaml",
           "",
           2,
           520.0,
           {"rejected sample of sensor 2 (unexpected_source: sensor_id = 2",
            "rejected sample of sensor 3 (unexpected_source: sensor_id = 3",
            "command 1 from 'fault-manager' refused: kind 8: sensor_id 2 is not this filter's IMU"},
           "fault_manager_triplex.yaml",
           1,
           "",
           "navbus/imu/increment_block 1:accepted 2:refused 3:refused"});
}

// The triplex aircraft with unit 1's gyro ramping (seed000_triplex_gyro_ramp.yaml) into the filter
// in three lanes (config/filter_triplex.yaml) beside the fault manager's parity test: the parity
// decision fails unit 1's axis, the selector leaves lane 1 at the decision's data time, and every
// published solution (its lane, reset counter and deltas included) is the offline run's bit for
// bit: the selection waits for the parity test's judgement of each time (FaultMonitorProgress
// imu_judged_up_to_gps_ns) and the command it names.
// The ramp starts at 100 s and grows four times faster than the demo's, so that 200 s of data
// hold the decision and the switch (the sanitizers' build runs it too).
TEST(OfflineEqualsBus, TriplexLanesSwitchWhereOfflineTheyDo) {
  runCase({84,
           "seed000_triplex_gyro_ramp.yaml",
           "filter_triplex.yaml",
           "",
           3,
           200.0,
           {"lanes: switched from IMU 1 to IMU", "switches 1,",
            "selections made without the parity test's judgement (its wait ran out) 0"},
           "fault_manager_triplex.yaml",
           1,
           "faults:\n  - {type: imu_bias_ramp, sensor: gyro, axis: x, start_s: 100,\n"
           "     slope_deg_per_h_per_s: 0.01, saturation_deg_per_h: 3, sensor_id: 1}\n",
           "navbus/imu/increment_block 1:accepted 2:accepted 3:accepted",
           "navbus/imu/increment 1:accepted 2:accepted 3:accepted"});
}

// The triplex with a fourth lane on the least-squares combination of all three units, preferred
// (config/filter_triplex_least_squares.yaml), and a 10 deg/h step on unit 2's x gyro at 100 s:
// the combination waits for the parity test's judgement of each time, so the failed gyro leaves
// it at the decision's data time and the lane re-learns there, on the bus as offline; that lane
// is published throughout (no switch), every solution bit for bit.
TEST(OfflineEqualsBus, TriplexLanesWithALeastSquaresLaneLeaveTheFailedGyroAsOffline) {
  runCase({123,
           "seed000_triplex.yaml",
           "filter_triplex_least_squares.yaml",
           "",
           3,
           200.0,
           {"least-squares lane 9: 20000 combined increments of 3 units (60000 taken), "
            "instruments taken out 1",
            "selected IMU 9, switches 0,",
            "selections made without the parity test's judgement (its wait ran out) 0"},
           "fault_manager_triplex.yaml",
           1,
           "faults:\n  - {type: imu_bias_step, sensor: gyro, axis: x, start_s: 100,\n"
           "     magnitude_deg_per_h: 10, sensor_id: 2}\n",
           "navbus/imu/increment_block 1:accepted 2:accepted 3:accepted",
           "navbus/imu/increment 1:accepted 2:accepted 3:accepted"});
}

// Two GNSS receivers (seed000_dual_receivers.yaml: receiver 2 beside the filter's receiver 1)
// with the fault manager's cross-receiver test: the simulator publishes receiver 2's epochs under
// its id, the filter refuses them (counted), the fault manager reads both reliably, and receiver
// 2's clock jump at 100 s is the one decision, field for field the offline one; the solutions
// are unchanged by it (decisions only).
TEST(OfflineEqualsBus, DualReceiversClockJumpDecidedAsOffline) {
  runCase({100,
           "seed000_dual_receivers_clock_jump.yaml",
           "filter_seed000_tc.yaml",
           "",
           3,
           120.0,
           {"unexpected_source: sensor_id = 2"},
           "fault_manager_dual_receivers.yaml",
           1,
           "faults:\n  - {type: receiver_clock_jump, start_s: 100, magnitude_ms: 1, receiver_id: "
           "2}\n",
           "navbus/gnss/observations 1:accepted 2:refused",
           "navbus/gnss/observations 1:accepted 2:accepted"});
}

// The loop closed for a receiver: receiver 1's clock, the one the filter fuses, jumps 1 ms at
// 100 s (seed000_dual_receivers_clock_jump_fused.yaml). The fault manager's cross-receiver test
// names it and commands the compensation at the instant before that epoch; the filter
// (config/filter_dual_receivers.yaml) fuses each epoch only once the fault manager has judged
// the time before it (FaultMonitorProgress gnss_judged_up_to_gps_ns), so the command takes effect
// before the jumped epoch on the bus as offline: the one decision, the command applied, and
// every solution the offline run's bit for bit (without the command the GLR took the jump for an
// accelerometer step and the solution ran 282 m off within 60 s). The data come in real time, as
// a receiver's do: each epoch reaches the filter and the fault manager together (without
// receivers_judged the filter fused the jumped epoch before the command came, and its solutions
// after it differed from offline's).
TEST(OfflineEqualsBus, FusedReceiversClockJumpCompensatedAsOffline) {
  runCase({117,
           "seed000_dual_receivers_clock_jump_fused.yaml",
           "filter_dual_receivers.yaml",
           "",
           3,
           16.0,
           {"command 1 from 'fault-manager' applied (kind 2)", "commands applied 1 refused ",
            "judgements waited for beyond the budget 0"},
           "fault_manager_dual_receivers.yaml",
           1,
           "faults:\n  - {type: receiver_clock_jump, start_s: 10, magnitude_ms: 1, receiver_id: "
           "1}\n",
           "navbus/gnss/observations 1:accepted 2:refused",
           "navbus/gnss/observations 1:accepted 2:accepted",
           true});
}

// A redundant receiver falls silent (seed000_dual_receivers.yaml, receiver 2 out from 10 s to
// 16 s, data in real time): the fault manager's watchdog declares its epochs LOST after 2 s and
// RESTORED when they return (two decisions on the bus only, wall-time judgements); the
// cross-receiver test goes on without it, so the filter, which waits for that test's judgement
// of each of its receiver's epochs, is not held beyond its budget; the filter does not fuse
// receiver 2, so its loss is not the filter's (no solution flagged FAULT_GNSS_STREAM_LOST, the
// exclusion refused as not its stream, and the fault manager not DEGRADED by that refusal).
// Every solution is the offline run's bit for bit.
TEST(OfflineEqualsBus, ASilentRedundantReceiverHoldsNothingAndFlagsNothing) {
  Case c{121,
         "seed000_dual_receivers.yaml",
         "filter_dual_receivers.yaml",
         "",
         3,
         24.0,
         {"judgements waited for beyond the budget 0", "is not a stream of this filter"},
         "fault_manager_dual_receivers.yaml",
         0,
         "faults:\n  - {type: gnss_outage, start_s: 10, duration_s: 6, receiver_id: 2}\n",
         "navbus/gnss/observations 1:accepted 2:refused",
         "navbus/gnss/observations 1:accepted 2:accepted",
         true};
  c.watched_receiver = 2;
  c.watchdog_decisions = 2;  // LOST, RESTORED
  c.fm_log_lacks = {"health DEGRADED"};
  runCase(c);
}

// The whole redundant installation (seed000_triplex_dual_receivers.yaml): three lanes, each
// waiting for both of the fault manager's judgements (the parity test's of the IMU data, the
// cross-receiver test's of the receivers' epochs), and receiver 1's clock jumping 1 ms at 100 s:
// the one decision, its command applied in every lane before the jumped epoch, and every
// published solution the offline run's bit for bit.
TEST(OfflineEqualsBus, TriplexLanesCompensateTheFusedReceiversClockAsOffline) {
  runCase({118,
           "seed000_triplex_dual_receivers.yaml",
           "filter_triplex_receivers.yaml",
           "",
           4,
           160.0,
           {"selections made without the parity test's judgement (its wait ran out) 0",
            // refusals not counted: the watchdog's end-of-data exclusions may be refused as
            // "ended as announced" (seen once in a full ctest run)
            "commands applied 1 refused "},
           "fault_manager_triplex_receivers.yaml",
           1,
           "faults:\n  - {type: receiver_clock_jump, start_s: 100, magnitude_ms: 1, receiver_id: "
           "1}\n",
           "navbus/gnss/observations 1:accepted 2:refused",
           "navbus/gnss/observations 1:accepted 2:accepted"});
}

// Every lane fed every receiver (config/filter_triplex_receivers_fused.yaml): three lanes, each
// fusing both receivers' epochs of a time as one stacked update (receiver 2 with its own clock
// states, started from its first epoch), and receiver 2's clock jumping 1 ms at 100 s: the one
// decision, its command applied to receiver 2's clock in every lane before the jumped epoch (a
// filter fusing receiver 1 alone refuses it), both receivers accepted, and every published
// solution the offline run's bit for bit.
TEST(OfflineEqualsBus, TriplexLanesFuseBothReceiversAndCompensateEitherClockAsOffline) {
  runCase({125,
           "seed000_triplex_dual_receivers.yaml",
           "filter_triplex_receivers_fused.yaml",
           "",
           4,
           160.0,
           {"selections made without the parity test's judgement (its wait ran out) 0",
            "further receivers' clocks started 1,",
            // refusals not counted: the watchdog's end-of-data exclusions may be refused as
            // "ended as announced"
            "commands applied 1 refused "},
           "fault_manager_triplex_receivers.yaml",
           1,
           "faults:\n  - {type: receiver_clock_jump, start_s: 100, magnitude_ms: 1, receiver_id: "
           "2}\n",
           "navbus/gnss/observations 1:accepted 2:accepted",
           "navbus/gnss/observations 1:accepted 2:accepted"});
}

// Two parallel units (seed000_dual_parallel.yaml), unit 1's x gyro stepping 10 deg/h at 100 s:
// the parity test cannot say which unit (one ambiguous decision) and names both as suspects
// (CMD_RELEARN_BIAS and CMD_SUSPECT_SENSOR_AXIS for each); both lanes re-learn that bias from the
// onset, and the selection, comparing their estimates at each time, names unit 1 and leaves its
// lane; the fault manager, reading the lanes' solutions, publishes the decision naming unit 1. The
// lanes wait for the parity test's judgement, which comes after its commands: the naming and the
// switch at the same data time on the bus as offline, every published solution bit for bit.
TEST(OfflineEqualsBus, ParallelLanesNameTheFaultyUnitAsOffline) {
  runCase(
      {120,
       "seed000_dual_parallel.yaml",
       "filter_dual_parallel.yaml",
       "",
       3,
       160.0,
       {"lanes: IMU 1 gyro axis x named at", "lanes: switched from IMU 1 to IMU 2", "switches 1,",
        "selections made without the parity test's judgement (its wait ran out) 0",
        "suspect units compared 1, named 1,",
        // lane IMU 1: its re-learn and both suspects (the lanes' commands, answered by lane 0);
        // refusals not counted here: at the end of the data the watchdog's best-effort reader
        // may miss the streams' dispose, and its exclusions are refused as "ended as announced"
        // (1 run in 12)
        "commands applied 3 refused "},
       "fault_manager_dual_parallel.yaml",
       2,  // the parity test's (ambiguous) and the fault manager's "lanes" naming unit 1
       "faults:\n  - {type: imu_bias_step, sensor: gyro, axis: x, start_s: 100,\n"
       "     magnitude_deg_per_h: 10, sensor_id: 1}\n",
       "navbus/imu/increment_block 1:accepted 2:accepted",
       "navbus/imu/increment 1:accepted 2:accepted"});
}

// Run-time switching of the fusion structure by CMD_SELECT_FUSION (seed 001): centralized ->
// federated -> adaptive, and a structure that does not apply is refused (the solution keeps the
// last one).
TEST(FusionSwitch, SelectFusionCommandsTakeEffectOverTheBus) {
  constexpr int kDomain = 88;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("fusion-switch");
  const std::string domain = "domain_id: " + std::to_string(kDomain) + "\n";
  const std::string sim_cfg = test::writeFile(
      dir / "sim.yaml", "extends: " + std::string(navbus::test_paths::scenarioDir()) +
                            "/seed001_leo.yaml\n" + domain +
                            "timing: {duration_s: 0, pacing: realtime,\n"
                            "  min_readers: {imu: 1, raw_imu: 0, gnss: 1, star_tracker: 1}}\n");
  const std::string filter_cfg = test::writeFile(
      dir / "filter.yaml", "extends: " + std::string(navbus::test_paths::configDir()) +
                               "/filter_seed001_lc.yaml\n" + domain);
  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "fusion-switch-test"), shutdown);
  std::vector<FusionStructure> seen;
  me.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) { seen.push_back(s.fusion()); });
  auto commands = me.createWriter<FilterCommandPubSubType>(bus::topic::kFilterCommand,
                                                           bus::profile::kDecisionWriter);
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  test::ChildProcess sim(navbus::test_paths::sensorSimExe(), {"-c", sim_cfg},
                         (dir / "sim.log").string());
  ASSERT_TRUE(test::spinUntil(me, 30s, [&] { return seen.size() >= 5; }))
      << test::readFile(dir / "filter.log");
  EXPECT_EQ(seen.back(), FUSION_CENTRALIZED);
  std::uint64_t id = 0;
  auto select = [&](FusionStructure f, const char* issuer = "operator") {
    FilterCommand c;
    c.command_id(++id);
    c.vehicle_id(1);
    c.kind(CMD_SELECT_FUSION);
    c.fusion(f);
    c.issuer(issuer);
    ASSERT_TRUE(commands.write(c));
  };
  for (FusionStructure f : {FUSION_FEDERATED, FUSION_ADAPTIVE}) {
    select(f);
    EXPECT_TRUE(test::spinUntil(me, 10s, [&] { return seen.back() == f; }))
        << "structure " << static_cast<int>(f) << " not reached";
  }
  select(FUSION_NONE);  // not a structure of a loosely coupled filter: refused
  // A valid request from an issuer the filter is not configured to obey: refused.
  select(FUSION_CENTRALIZED, "intruder");
  const std::size_t before = seen.size();
  test::spinUntil(me, 10s, [&] { return seen.size() >= before + 10; });
  EXPECT_EQ(seen.back(), FUSION_ADAPTIVE);
  sim.signal(SIGTERM);
  filter.signal(SIGTERM);
  EXPECT_EQ(sim.wait(10s), 0);
  EXPECT_EQ(filter.wait(10s), 0);
  const std::string log = test::readFile(dir / "filter.log");
  EXPECT_NE(log.find("refused"), std::string::npos) << log;
  EXPECT_NE(log.find("commands applied 2 refused 2 (unauthorized issuer 1, issuer not the writer's "
                     "identity 0, stale 0)"),
            std::string::npos)
      << log;
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}

// The fault loop over the bus (seed 000, 35 s in real time): a 25 m/s pseudorange ramp on
// sv 13 from 20 s -> the fault manager's GLR decides (detector "glr", sv 13, ramp, onset) ->
// it commands the exclusion of sv 13's pseudorange -> the filter takes the command in its
// deterministic order, restores itself to before the onset and re-processes -> the solution
// is flagged and recovers. Decision and solutions are read by this test's subscribers, and the
// solutions are bit-identical to `navbus offline` running the same loop in one process.
TEST(FaultLoop, RampDetectedExcludedAndRecoveredOverTheBusAsOffline) {
  constexpr int kDomain = 89;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("fault-loop");
  const test::Seed000Loop cfg =
      test::writeSeed000Loop(dir, kDomain,
                             "timing: {duration_s: 35, pacing: realtime}\n"
                             "faults:\n  - {type: pseudorange_ramp, sv_id: 13, start_s: 20, "
                             "slope_mps: 25, saturation_m: 250}\n");
  const std::string& sim_cfg = cfg.sim;
  const std::string& filter_cfg = cfg.filter;
  const std::string& fm_cfg = cfg.fault_manager;
  ASSERT_EQ(test::runOffline(cfg, dir), 0) << test::readFile(dir / "offline.log");
  const std::vector<std::string> expected = test::csvDataRows(dir / "offline" / "solution.csv");
  ASSERT_EQ(expected.size(), 350u);

  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "fault-loop-test"), shutdown);
  std::vector<std::string> rows;
  std::vector<NavigationSolution> solutions;
  std::vector<FaultDecision> decisions;
  std::vector<FilterCommand> commands;
  me.subscribe<NavigationSolutionPubSubType>(bus::topic::kNavSolution,
                                             bus::profile::kSolutionReader,
                                             [&](const NavigationSolution& s, const auto&) {
                                               if (s.mode() == MODE_INERTIAL_LOST) return;
                                               rows.push_back(records::csvRows(s).at(0));
                                               solutions.push_back(s);
                                             });
  me.subscribe<FaultDecisionPubSubType>(
      bus::topic::kFaultDecision, bus::profile::kDecisionReader,
      [&](const FaultDecision& d, const auto&) { decisions.push_back(d); });
  me.subscribe<FilterCommandPubSubType>(
      bus::topic::kFilterCommand, bus::profile::kDecisionReader,
      [&](const FilterCommand& c, const auto&) { commands.push_back(c); });
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  test::ChildProcess fm(navbus::test_paths::faultManagerExe(), {"-c", fm_cfg},
                        (dir / "fm.log").string());
  test::ChildProcess sim(navbus::test_paths::sensorSimExe(), {"-c", sim_cfg},
                         (dir / "sim.log").string());
  while (sim.running()) me.spinOnce(50ms);
  EXPECT_EQ(sim.wait(1s), 0) << test::readFile(dir / "sim.log");
  test::spinUntil(me, 20s, [&] { return rows.size() >= expected.size(); });
  me.spinOnce(500ms);
  filter.signal(SIGTERM);
  fm.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  EXPECT_EQ(fm.wait(10s), 0);
  const std::string filter_log = test::readFile(dir / "filter.log");

  // The decision: the GLR isolated sv 13's pseudorange as a ramp near 25 m/s, onset near 20 s.
  const auto glr = std::find_if(decisions.begin(), decisions.end(), [](const FaultDecision& d) {
    return d.detector() == "glr" && d.event() == EVENT_FAULT_DETECTED;
  });
  ASSERT_NE(glr, decisions.end()) << test::readFile(dir / "fm.log");
  EXPECT_EQ(glr->source(), SOURCE_SATELLITE);
  EXPECT_EQ(glr->sv_id(), 13);
  EXPECT_GE(glr->test_statistic(), glr->threshold());
  const double start_s = 1.4e9;
  const double decided_s = 1e-9 * static_cast<double>(glr->time_gps_ns()) - start_s;
  const double onset_s = 1e-9 * static_cast<double>(glr->onset_time_gps_ns()) - start_s;
  EXPECT_GT(decided_s, 20.0);
  EXPECT_LT(decided_s, 30.0);
  EXPECT_NEAR(onset_s, 20.0, 2.0);
  // The command that follows it.
  const auto exclusion =
      std::find_if(commands.begin(), commands.end(), [&](const FilterCommand& c) {
        return c.kind() == CMD_EXCLUDE_SATELLITE && c.decision_id() == glr->decision_id();
      });
  ASSERT_NE(exclusion, commands.end());
  EXPECT_EQ(exclusion->sv_id(), 13);
  EXPECT_EQ(exclusion->scope(), SCOPE_PSEUDORANGE);
  // The filter acted on it in order (not late), from before the onset.
  EXPECT_NE(filter_log.find("late 0"), std::string::npos) << filter_log;
  EXPECT_NE(filter_log.find("recoveries from onset 1"), std::string::npos) << filter_log;
  // ... and answered it over the bus: the fault manager knows its command was applied.
  const std::string fm_log = test::readFile(dir / "fm.log");
  EXPECT_NE(fm_log.find("(the filter applied 1, clamped 0, refused 0)"), std::string::npos)
      << fm_log;
  // The solutions after the decision carry the exclusion flag.
  ASSERT_FALSE(solutions.empty());
  EXPECT_TRUE(solutions.back().active_fault_flags() & FAULT_SATELLITE_EXCLUDED);
  // The offline loop's error after the decision: back to the fault-free level.
  {
    std::ifstream in(dir / "offline" / "error.csv");
    std::string line;
    std::getline(in, line);
    double worst_after = 0.0;
    while (std::getline(in, line)) {
      std::vector<double> v;
      std::stringstream ss(line);
      std::string cell;
      while (std::getline(ss, cell, ',')) v.push_back(std::atof(cell.c_str()));
      const double t = 1e-9 * v[0] - start_s;
      const double err = std::sqrt(v[2] * v[2] + v[3] * v[3] + v[4] * v[4]);
      if (t > decided_s + 1.0) worst_after = std::max(worst_after, err);
    }
    EXPECT_LT(worst_after, 60.0) << "3-D position error after the exclusion";
  }
  // Bus and offline: the same loop, the same bits.
  ASSERT_EQ(rows.size(), expected.size()) << filter_log;
  const std::size_t differing = test::countDiffering(rows, expected);
  EXPECT_EQ(differing, 0u);
  std::printf("fault loop: decision at %.1f s (onset %.1f s), %zu solutions bit-identical: %s\n",
              decided_s, onset_s, rows.size(), differing == 0 ? "yes" : "NO");
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}

TEST(FaultLoop, StuckAccelerometerFlaggedByTheDitherMonitorOverTheBus) {
  constexpr int kDomain = 90;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("dither-loop");
  const std::string src = navbus::test_paths::sourceDir();
  const std::string domain = "domain_id: " + std::to_string(kDomain) + "\n";
  // Seed 003: the static laser INS with accelerometer x stuck at 8 s, in real time: the
  // target (flagged within 0.5 s of the fault) is a data-time latency, which a fast-paced
  // simulator running ahead of the fault manager's command would turn into a race.
  constexpr double kStuckS = 8.0, kEndS = 12.0;
  const std::string sim_cfg = test::writeFile(
      dir / "sim.yaml",
      "extends: " + src + "/sim/scenarios/seed003_laser_ins.yaml\n" + domain +
          "timing: {duration_s: 12, pacing: realtime}\n"
          "faults:\n  - {type: sensor_stuck, sensor: accelerometer, axis: x, start_s: 8}\n");
  const std::string filter_cfg = test::writeFile(
      dir / "filter.yaml", "extends: " + src + "/config/filter.yaml\n" + domain +
                               "initial_state: {latitude_deg: 36.4, longitude_deg: 127.4, "
                               "height_m: 60.0}\n");
  const std::string fm_cfg =
      test::writeFile(dir / "fm.yaml", "extends: " + src + "/config/fault_manager.yaml\n" + domain);

  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "dither-loop-test"), shutdown);
  std::vector<NavigationSolution> solutions;
  std::vector<FaultDecision> decisions;
  std::vector<FilterCommand> commands;
  me.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) { solutions.push_back(s); });
  me.subscribe<FaultDecisionPubSubType>(
      bus::topic::kFaultDecision, bus::profile::kDecisionReader,
      [&](const FaultDecision& d, const auto&) { decisions.push_back(d); });
  me.subscribe<FilterCommandPubSubType>(
      bus::topic::kFilterCommand, bus::profile::kDecisionReader,
      [&](const FilterCommand& c, const auto&) { commands.push_back(c); });
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  test::ChildProcess fm(navbus::test_paths::faultManagerExe(), {"-c", fm_cfg},
                        (dir / "fm.log").string());
  test::ChildProcess sim(navbus::test_paths::sensorSimExe(), {"-c", sim_cfg},
                         (dir / "sim.log").string());
  while (sim.running()) me.spinOnce(50ms);
  EXPECT_EQ(sim.wait(1s), 0) << test::readFile(dir / "sim.log");
  test::spinUntil(me, 20s, [&] {
    return !solutions.empty() &&
           1e-9 * static_cast<double>(solutions.back().time_gps_ns()) - 1.4e9 >= kEndS - 0.01;
  });
  me.spinOnce(500ms);
  filter.signal(SIGTERM);
  fm.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  EXPECT_EQ(fm.wait(10s), 0);

  // The decision: dither-fft, accelerometer x, within 0.5 s of the fault, with its evidence.
  const double start_s = 1.4e9;
  std::vector<FaultDecision> dither;
  std::copy_if(decisions.begin(), decisions.end(), std::back_inserter(dither),
               [](const FaultDecision& d) { return d.detector() == "dither-fft"; });
  ASSERT_EQ(dither.size(), 1u) << test::readFile(dir / "fm.log");
  const FaultDecision& d = dither.front();
  EXPECT_EQ(d.event(), EVENT_FAULT_DETECTED);
  EXPECT_EQ(d.source(), SOURCE_ACCELEROMETER);
  EXPECT_EQ(d.axis(), 0);
  const double decided_s = 1e-9 * static_cast<double>(d.time_gps_ns()) - start_s;
  EXPECT_GT(decided_s, kStuckS);
  EXPECT_LE(decided_s, kStuckS + 0.5);
  EXPECT_LE(1e-9 * static_cast<double>(d.onset_time_gps_ns()) - start_s, kStuckS);
  EXPECT_GT(d.test_statistic(), d.threshold());  // the peak is off every line (or absent)
  EXPECT_EQ(d.dither().expected_frequency_hz()[0], 373.0);
  // The command, and the filter acting on it: solutions flagged from the decision on, not before.
  const auto fail = std::find_if(commands.begin(), commands.end(), [&](const FilterCommand& c) {
    return c.kind() == CMD_FAIL_SENSOR_AXIS && c.decision_id() == d.decision_id();
  });
  ASSERT_NE(fail, commands.end());
  EXPECT_EQ(fail->sensor(), SOURCE_ACCELEROMETER);
  EXPECT_EQ(fail->axis(), 0);
  int flagged_before = 0, flagged_after = 0, after = 0;
  for (const auto& s : solutions) {
    const double t = 1e-9 * static_cast<double>(s.time_gps_ns()) - start_s;
    const bool flagged = (s.active_fault_flags() & FAULT_IMU_AXIS_FAILED) != 0;
    if (t < kStuckS) flagged_before += flagged ? 1 : 0;
    if (t > decided_s + 0.1 && s.mode() != MODE_INERTIAL_LOST) {
      ++after;
      flagged_after += flagged ? 1 : 0;
    }
  }
  EXPECT_EQ(flagged_before, 0);
  EXPECT_GT(after, 30);  // 10 Hz solutions for the ~3.7 s left
  EXPECT_EQ(flagged_after, after);
  std::printf(
      "dither loop: accelerometer x stuck at %.0f s, decided at %.3f s, %d of %d later "
      "solutions flagged\n",
      kStuckS, decided_s, flagged_after, after);
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}
