// `navbus record` then `navbus replay` into a new filter: the seed-004 land vehicle published by
// the simulator is recorded from the bus (every sensor topic, as CSV), then replayed as fast as
// the readers take it into navbus-filter and the fault manager. The filter's solutions must be
// bit-identical to `navbus offline` on the same scenario, seed and configuration: the replay
// reproduced every input bit for bit, with nothing lost. Domain 66. (Also: the real car and
// walk, a reader behind, and a recording of three IMUs through lanes, domain 110.)
#include <algorithm>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <regex>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "harness.hpp"
#include "navbus/records/formatters.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace std::chrono_literals;

namespace {

std::size_t dataRows(const std::filesystem::path& file) {
  return test::csvDataRows(file).size();
}

/// The simulator's run on `domain`, recorded from the bus into dir/rec (every sensor topic, as
/// CSV; the recorder is its only reader); returns the simulator's exit code, or the recorder's
/// if the simulator's is 0 (nullopt: one did not end; logs in dir/sim.log and dir/record.log).
std::optional<int> recordSimulatorRun(int domain, const std::filesystem::path& dir,
                                      const std::string& sim_cfg, const std::string& seed) {
  test::ChildProcess recorder(
      navbus::test_paths::toolExe(),
      {"-d", std::to_string(domain), "record", "navbus/imu/increment_block", "navbus/imu/raw",
       "navbus/gnss/observations_block", "navbus/gnss/fix_block", "-o", (dir / "rec").string()},
      (dir / "record.log").string());
  test::ChildProcess sim(navbus::test_paths::sensorSimExe(), {"-c", sim_cfg, "--seed", seed},
                         (dir / "sim.log").string());
  const std::optional<int> sim_exit = sim.wait(120s);
  std::this_thread::sleep_for(1s);  // the recorder writes what it took last
  recorder.signal(SIGTERM);
  const std::optional<int> recorder_exit = recorder.wait(10s);
  return sim_exit != 0 ? sim_exit : recorder_exit;
}

/// `navbus replay dir/rec --speed 0` on `domain`, once the readers `min_readers` counts (topic,
/// readers) are matched; its log in dir/replay.log.
std::unique_ptr<test::ChildProcess> startReplay(
    int domain, const std::filesystem::path& dir,
    const std::vector<std::pair<std::string, int>>& min_readers) {
  std::vector<std::string> args = {
      "-d", std::to_string(domain), "replay", (dir / "rec").string(), "--speed", "0"};
  for (const auto& [topic, n] : min_readers) {
    args.push_back("--min-readers");
    args.push_back(topic + "=" + std::to_string(n));
  }
  return std::make_unique<test::ChildProcess>(navbus::test_paths::toolExe(), args,
                                              (dir / "replay.log").string());
}

}  // namespace

TEST(Replay, RecordedRunReplaysIntoANewFilterBitIdentical) {
  constexpr int kDomain = 66;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("replay");
  const std::string src = navbus::test_paths::sourceDir();
  const std::string domain = "domain_id: " + std::to_string(kDomain) + "\n";
  const std::string sim_cfg = test::writeFile(
      dir / "sim.yaml", "extends: " + src + "/sim/scenarios/seed004_land_vehicle.yaml\n" + domain +
                            "timing: {duration_s: 60, min_readers: {imu: 1, raw_imu: 1, gnss: 1, "
                            "star_tracker: 0}}\n");
  const std::string filter_cfg = test::writeFile(
      dir / "filter.yaml", "extends: " + src + "/config/filter_seed004_mdf.yaml\n" + domain +
                               "solution_writer_profile: navbus_solution_writer_lossless\n"
                               "sequencer_max_wait_s: 30\n");
  const std::string fm_cfg = test::writeFile(dir / "fm.yaml", domain);

  test::ChildProcess offline(navbus::test_paths::toolExe(),
                             {"offline", "--scenario", sim_cfg, "--filter", filter_cfg, "--start",
                              "config", "--seed", "5", "-o", (dir / "offline").string()},
                             (dir / "offline.log").string());
  ASSERT_EQ(offline.wait(120s), 0) << test::readFile(dir / "offline.log");
  const std::vector<std::string> expected = test::csvDataRows(dir / "offline" / "solution.csv");
  ASSERT_GT(expected.size(), 500u);

  // 1. The simulator's run, recorded from the bus (the recorder is its only reader).
  ASSERT_EQ(recordSimulatorRun(kDomain, dir, sim_cfg, "5"), 0)
      << test::readFile(dir / "sim.log") << test::readFile(dir / "record.log");
  // 60 s of 50 Hz increments in blocks of 0.3 s (a CSV row per increment); the scenario's
  // GNSS fixes (in blocks too, a row per fix) as the simulator reports them.
  const std::string record_log = test::readFile(dir / "record.log");
  EXPECT_NE(record_log.find("recorded 200 samples of navbus/imu/increment_block"),
            std::string::npos)
      << record_log;
  EXPECT_EQ(dataRows(dir / "rec" / "navbus_imu_increment_block.csv"), 3000u);
  EXPECT_NE(test::readFile(dir / "sim.log")
                .find(std::to_string(dataRows(dir / "rec" / "navbus_gnss_fix_block.csv")) +
                      " GNSS fixes"),
            std::string::npos);

  // 2. The recording replayed into a new filter and fault manager.
  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "replay-test"), shutdown);
  std::vector<std::string> rows;
  me.subscribe<NavigationSolutionPubSubType>(bus::topic::kNavSolution,
                                             bus::profile::kSolutionReader,
                                             [&](const NavigationSolution& s, const auto&) {
                                               if (s.mode() != MODE_INERTIAL_LOST)
                                                 rows.push_back(records::csvRows(s).at(0));
                                             });
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  test::ChildProcess fm(navbus::test_paths::faultManagerExe(), {"-c", fm_cfg},
                        (dir / "fm.log").string());
  const auto replay = startReplay(kDomain, dir,
                                  {{"navbus/imu/increment_block", 2},
                                   {"navbus/gnss/observations_block", 2},
                                   {"navbus/gnss/fix_block", 2}});
  while (replay->running()) me.spinOnce(50ms);
  const std::string replay_log = test::readFile(dir / "replay.log");
  EXPECT_EQ(replay->wait(1s), 0) << replay_log;
  EXPECT_NE(replay_log.find("replayed 200 of 200 samples of navbus/imu/increment_block"),
            std::string::npos)
      << replay_log;
  test::spinUntil(me, 60s, [&] { return rows.size() >= expected.size(); });
  me.spinOnce(500ms);
  filter.signal(SIGTERM);
  fm.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  EXPECT_EQ(fm.wait(10s), 0);

  ASSERT_EQ(rows.size(), expected.size()) << test::readFile(dir / "filter.log");
  const std::size_t differing = test::countDiffering(rows, expected);
  EXPECT_EQ(differing, 0u) << test::readFile(dir / "filter.log") << test::readFile(dir / "fm.log")
                           << replay_log;
  std::printf("replay of a recording: %zu solutions, bit-identical to offline: %s\n", rows.size(),
              differing == 0 ? "yes" : "NO");
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}

// The real car (config/datasets/drive_0708.yaml) imported, then replayed as fast as the
// readers take it into navbus-filter and the fault manager: the same solutions as `navbus
// offline --recording`, bit for bit, over 549 s of real, irregular IMU intervals. Domain 68.
TEST(Replay, TheImportedRealDriveReplaysBitIdentical) {
  constexpr int kDomain = 68;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("replay-real");
  const std::string src = navbus::test_paths::sourceDir();
  const std::string domain = "domain_id: " + std::to_string(kDomain) + "\n";
  const std::string filter_cfg = test::writeFile(
      dir / "filter.yaml", "extends: " + src + "/config/filter_drive_0708.yaml\n" + domain +
                               "solution_writer_profile: navbus_solution_writer_lossless\n"
                               "sequencer_max_wait_s: 30\n");
  const std::string fm_cfg = test::writeFile(dir / "fm.yaml", domain);
  const std::string rec = (dir / "rec").string();
  test::ChildProcess import(navbus::test_paths::toolExe(),
                            {"import", src + "/config/datasets/drive_0708.yaml", "-o", rec},
                            (dir / "import.log").string());
  ASSERT_EQ(import.wait(60s), 0) << test::readFile(dir / "import.log");
  test::ChildProcess offline(
      navbus::test_paths::toolExe(),
      {"offline", "--recording", rec, "--filter", filter_cfg, "-o", (dir / "offline").string()},
      (dir / "offline.log").string());
  ASSERT_EQ(offline.wait(120s), 0) << test::readFile(dir / "offline.log");
  const std::vector<std::string> expected = test::csvDataRows(dir / "offline" / "solution.csv");
  ASSERT_GT(expected.size(), 45'000u);

  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "replay-real-test"), shutdown);
  std::vector<std::string> rows;
  me.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) { rows.push_back(records::csvRows(s).at(0)); });
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  test::ChildProcess fm(navbus::test_paths::faultManagerExe(), {"-c", fm_cfg},
                        (dir / "fm.log").string());
  test::ChildProcess replay(
      navbus::test_paths::toolExe(),
      {"-d", std::to_string(kDomain), "replay", rec, "--speed", "0", "--min-readers",
       "navbus/imu/increment_block=2", "--min-readers", "navbus/gnss/fix=2"},
      (dir / "replay.log").string());
  while (replay.running()) me.spinOnce(50ms);
  const std::string replay_log = test::readFile(dir / "replay.log");
  EXPECT_EQ(replay.wait(1s), 0) << replay_log;
  EXPECT_NE(replay_log.find("replayed 6054 of 6054 samples of navbus/imu/increment_block"),
            std::string::npos)
      << replay_log;
  test::spinUntil(me, 120s, [&] { return rows.size() >= expected.size(); });
  me.spinOnce(500ms);
  filter.signal(SIGTERM);
  fm.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  EXPECT_EQ(fm.wait(10s), 0);

  ASSERT_EQ(rows.size(), expected.size()) << test::readFile(dir / "filter.log");
  const std::size_t differing = test::countDiffering(rows, expected);
  EXPECT_EQ(differing, 0u) << test::readFile(dir / "filter.log");
  std::printf("real drive replayed over the bus: %zu solutions, bit-identical to offline: %s\n",
              rows.size(), differing == 0 ? "yes" : "NO");
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}

// The real walk (config/datasets/walk_0827.yaml) imported with a 2 m/s ramp in G10's
// pseudoranges from 40 s, then replayed as fast as the readers take it into navbus-filter
// (tightly coupled on the walk's own pseudoranges and Doppler) and the fault manager (the GLR):
// the same commands and solutions as `navbus offline --recording ... --fault-manager`, bit for
// bit, apart from the wall-clock FAULT_NO_FAULT_MONITOR flag before the fault manager's first
// report. The filter waits for its judgements from the first epoch on
// (fault_monitor.judged_from_start in the walk's configuration). Domain 69.
TEST(Replay, TheImportedRealWalkWithARampReplaysBitIdentical) {
  constexpr int kDomain = 69;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("replay-walk");
  const std::string src = navbus::test_paths::sourceDir();
  const std::string domain = "domain_id: " + std::to_string(kDomain) + "\n";
  const std::string filter_cfg = test::writeFile(
      dir / "filter.yaml", "extends: " + src + "/config/filter_walk_0827_tc.yaml\n" + domain +
                               "solution_writer_profile: navbus_solution_writer_lossless\n"
                               "sequencer_max_wait_s: 30\n");
  const std::string fm_cfg =
      test::writeFile(dir / "fm.yaml", "extends: " + src + "/config/fault_manager.yaml\n" + domain);
  const std::string rec = (dir / "rec").string();
  test::ChildProcess import(
      navbus::test_paths::toolExe(),
      {"import", src + "/config/datasets/walk_0827.yaml", "-o", rec, "--ramp", "10,2,40"},
      (dir / "import.log").string());
  ASSERT_EQ(import.wait(60s), 0) << test::readFile(dir / "import.log");
  test::ChildProcess offline(navbus::test_paths::toolExe(),
                             {"offline", "--recording", rec, "--filter", filter_cfg,
                              "--fault-manager", fm_cfg, "-o", (dir / "offline").string()},
                             (dir / "offline.log").string());
  ASSERT_EQ(offline.wait(120s), 0) << test::readFile(dir / "offline.log");
  const std::vector<std::string> expected = test::csvDataRows(dir / "offline" / "solution.csv");
  const std::vector<std::string> expected_commands =
      test::csvDataRows(dir / "offline" / "commands.csv");
  ASSERT_GT(expected.size(), 5'000u);
  ASSERT_FALSE(expected_commands.empty());

  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "replay-walk-test"), shutdown);
  // FAULT_NO_FAULT_MONITOR is the filter's wall-clock view of the fault manager's health
  // reports, outside bus = offline (docs/architecture.md): counted, then left out of the
  // comparison.
  // Once a solution is under the monitor's watch, every later one is: the fault manager judges
  // each epoch before the filter goes on (also where a GNSS epoch falls between increments).
  std::vector<std::string> rows;
  std::size_t no_monitor = 0;
  std::size_t no_monitor_once_watched = 0;
  bool watched = false;
  me.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) {
        NavigationSolution compared = s;
        if ((s.active_fault_flags() & FAULT_NO_FAULT_MONITOR) != 0) {
          ++no_monitor;
          no_monitor_once_watched += watched ? 1 : 0;
          compared.active_fault_flags(s.active_fault_flags() & ~FAULT_NO_FAULT_MONITOR);
        } else {
          watched = true;
        }
        rows.push_back(records::csvRows(compared).at(0));
      });
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  test::ChildProcess fm(navbus::test_paths::faultManagerExe(), {"-c", fm_cfg},
                        (dir / "fm.log").string());
  test::ChildProcess replay(
      navbus::test_paths::toolExe(),
      {"-d", std::to_string(kDomain), "replay", rec, "--speed", "0", "--min-readers",
       "navbus/imu/increment_block=2", "--min-readers", "navbus/gnss/observations=2"},
      (dir / "replay.log").string());
  while (replay.running()) me.spinOnce(50ms);
  const std::string replay_log = test::readFile(dir / "replay.log");
  EXPECT_EQ(replay.wait(1s), 0) << replay_log;
  test::spinUntil(me, 120s, [&] { return rows.size() >= expected.size(); });
  me.spinOnce(500ms);
  filter.signal(SIGTERM);
  fm.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  EXPECT_EQ(fm.wait(10s), 0);

  ASSERT_EQ(rows.size(), expected.size()) << test::readFile(dir / "filter.log");
  const std::size_t differing = test::countDiffering(rows, expected);
  EXPECT_EQ(differing, 0u) << test::readFile(dir / "filter.log") << test::readFile(dir / "fm.log");
  EXPECT_TRUE(watched);
  EXPECT_EQ(no_monitor_once_watched, 0u);
  // The ramp's exclusion of G10 and every other command, applied as offline. The fault
  // manager's real-time watchdog may also call the IMU stream lost once the replay has ended
  // (slowed down, e.g. under the sanitizers): the filter refuses that, the stream having ended
  // as announced, and nothing else.
  const std::string filter_log = test::readFile(dir / "filter.log");
  std::smatch counts;
  ASSERT_TRUE(std::regex_search(filter_log, counts,
                                std::regex("commands applied ([0-9]+) refused ([0-9]+)")))
      << filter_log;
  EXPECT_EQ(std::stoul(counts[1]), expected_commands.size()) << filter_log;
  const std::regex ended_as_announced("refused: navbus/[a-z_/]+ id [0-9]+ ended as announced");
  const auto refusals_of_an_ended_stream = static_cast<std::size_t>(
      std::distance(std::sregex_iterator(filter_log.begin(), filter_log.end(), ended_as_announced),
                    std::sregex_iterator()));
  EXPECT_EQ(std::stoul(counts[2]), refusals_of_an_ended_stream) << filter_log;
  EXPECT_NE(test::readFile(dir / "offline" / "commands.csv").find("EXCLUDE_SATELLITE,1,"),
            std::string::npos);
  std::printf(
      "real walk with a ramp over the bus: %zu solutions bit-identical to offline: %s "
      "(%zu flagged 'no fault monitor' before the first judgement); %zu commands applied\n",
      rows.size(), differing == 0 ? "yes" : "NO", no_monitor, expected_commands.size());
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}

// A reader that stops taking (a stalled process) must slow the replay down, not lose samples:
// the real drive's 2,197 GNSS fixes replayed as fast as possible to a reader that takes nothing
// for 3 s. Its history (1,000 fixes) and the writer's (500) fill, so writes stay blocked for
// longer than the profile's max_blocking_time (1 s); the replay tries them again until the
// reader takes. Every fix must arrive, in order, and the replay must say it waited. Domain 109.
TEST(Replay, AReaderThatFallsBehindSlowsTheReplayDownWithoutLosingSamples) {
  constexpr int kDomain = 109;
  constexpr std::size_t kFixes = 2197;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("replay-slow-reader");
  const std::string rec = (dir / "rec").string();
  test::ChildProcess import(
      navbus::test_paths::toolExe(),
      {"import", std::string(navbus::test_paths::configDir()) + "/datasets/drive_0708.yaml", "-o",
       rec},
      (dir / "import.log").string());
  ASSERT_EQ(import.wait(60s), 0) << test::readFile(dir / "import.log");

  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "replay-slow-reader-test"), shutdown);
  std::vector<std::uint64_t> times_ns;
  me.subscribe<GnssFixPubSubType>(
      bus::topic::kGnssFix, bus::profile::kMeasurementReader,
      [&](const GnssFix& f, const auto&) { times_ns.push_back(f.time_gps_ns()); });
  test::ChildProcess replay(
      navbus::test_paths::toolExe(),
      {"-d", std::to_string(kDomain), "replay", rec, "--topics", "navbus/gnss/fix", "--speed", "0"},
      (dir / "replay.log").string());
  std::this_thread::sleep_for(3s);  // nothing taken: the reader has fallen behind
  while (replay.running()) me.spinOnce(50ms);
  test::spinUntil(me, 10s, [&] { return times_ns.size() >= kFixes; });
  const std::string replay_log = test::readFile(dir / "replay.log");
  EXPECT_EQ(replay.wait(1s), 0) << replay_log;
  std::smatch waits;
  ASSERT_TRUE(std::regex_search(
      replay_log, waits,
      std::regex("replayed 2197 of 2197 samples of navbus/gnss/fix \\(writes that waited for a "
                 "reader behind: ([0-9]+)\\)")))
      << replay_log;
  EXPECT_GT(std::stoul(waits[1]), 0u) << "the reader never held the writer up: nothing tested";
  EXPECT_EQ(times_ns.size(), kFixes);
  EXPECT_TRUE(std::is_sorted(times_ns.begin(), times_ns.end()));
  EXPECT_EQ(std::adjacent_find(times_ns.begin(), times_ns.end()), times_ns.end());
  std::printf("replay to a reader 3 s behind: %zu of %zu fixes taken, %lu writes waited\n",
              times_ns.size(), kFixes, std::stoul(waits[1]));
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}

// A recording of redundant IMUs (the triplex, three units in one recording, keyed by sensor
// id) through the whole loop: `navbus offline --recording` equals `navbus offline --scenario`
// on the same run (solutions, every lane's, the parity decision and its command), and the
// recording replayed as fast as the readers take it into navbus-filter (three lanes) and the
// fault manager (the parity test) equals both, bit for bit. Every unit's stream ends as the
// replay announces it (no watchdog loss at the end). Domain 110.
TEST(Replay, ATriplexRecordingReplaysEveryLaneBitIdentical) {
  constexpr int kDomain = 110;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("replay-triplex");
  const std::string src = navbus::test_paths::sourceDir();
  const std::string domain = "domain_id: " + std::to_string(kDomain) + "\n";
  // Unit 1's gyro ramps from 100 s: the parity test fails it near 126 s, the lanes switch.
  const std::string sim_cfg = test::writeFile(
      dir / "sim.yaml",
      "extends: " + src + "/sim/scenarios/seed000_triplex_gyro_ramp.yaml\n" + domain +
          "timing: {duration_s: 200, pacing: fast, min_readers: {imu: 1, raw_imu: 1, gnss: 1, "
          "gnss_fix: 1, star_tracker: 0}}\n"
          "faults:\n  - {type: imu_bias_ramp, sensor: gyro, axis: x, start_s: 100,\n"
          "     slope_deg_per_h_per_s: 0.01, saturation_deg_per_h: 3, sensor_id: 1}\n");
  const std::string filter_cfg = test::writeFile(
      dir / "filter.yaml",
      "extends: " + src + "/config/filter_triplex.yaml\n" + domain +
          "solution_writer_profile: navbus_solution_writer_lossless\n"
          "sequencer_max_wait_s: 30\n"
          // The monitor's liveness is wall-clock (3 s in the file): under the sanitizers a
          // starved fault manager's reports came further apart, and 516 solutions said
          // NOT_MONITORED where offline's carried the protection level. As offline_equals_bus.
          "fault_monitor: {participant: navbus-fault-manager, timeout_s: 30, "
          "judged_from_start: true}\n");
  const std::string fm_cfg = test::writeFile(
      dir / "fm.yaml", "extends: " + src + "/config/fault_manager_triplex.yaml\n" + domain);

  // 1. The simulator's run, recorded from the bus.
  const std::string rec = (dir / "rec").string();
  ASSERT_EQ(recordSimulatorRun(kDomain, dir, sim_cfg, "3"), 0)
      << test::readFile(dir / "sim.log") << test::readFile(dir / "record.log");
  // 200 s of three units at 100 Hz in blocks of 30 increments (the last of each unit 20).
  EXPECT_NE(test::readFile(dir / "record.log")
                .find("recorded 2001 samples of navbus/imu/increment_block"),
            std::string::npos)
      << test::readFile(dir / "record.log");

  // 2. Offline from the recording equals offline from the scenario.
  const auto offline = [&](const std::string& name, std::vector<std::string> input) {
    std::vector<std::string> args = {"offline"};
    args.insert(args.end(), input.begin(), input.end());
    for (const std::string& a :
         {std::string("--filter"), filter_cfg, std::string("--fault-manager"), fm_cfg,
          std::string("-o"), (dir / name).string()})
      args.push_back(a);
    test::ChildProcess run(navbus::test_paths::toolExe(), args, (dir / (name + ".log")).string());
    return run.wait(120s);
  };
  ASSERT_EQ(offline("scenario", {"--scenario", sim_cfg, "--start", "config", "--seed", "3"}), 0)
      << test::readFile(dir / "scenario.log");
  ASSERT_EQ(offline("recording", {"--recording", rec}), 0) << test::readFile(dir / "recording.log");
  const std::vector<std::string> expected = test::csvDataRows(dir / "recording" / "solution.csv");
  const std::vector<std::string> expected_lanes =
      test::csvDataRows(dir / "recording" / "lanes.csv");
  const std::vector<std::string> expected_decisions =
      test::csvDataRows(dir / "recording" / "decisions.csv");
  ASSERT_EQ(expected.size(), 2000u);
  ASSERT_EQ(expected_lanes.size(), 6000u);
  ASSERT_EQ(expected_decisions.size(), 1u) << "the parity test fails unit 1";
  EXPECT_EQ(expected, test::csvDataRows(dir / "scenario" / "solution.csv"));
  // The same lane solutions. Their order in the file is the order the lanes published them,
  // which follows the inputs' arrival: a recorded 0.3 s block of increments comes in at its
  // newest increment's time, after the epochs it spans, where the scenario gives each epoch
  // after its own increment (measured: the same 6000 rows, two of lane 1's later).
  const auto sorted = [](std::vector<std::string> rows) {
    std::sort(rows.begin(), rows.end());
    return rows;
  };
  EXPECT_EQ(sorted(expected_lanes), sorted(test::csvDataRows(dir / "scenario" / "lanes.csv")));
  EXPECT_EQ(expected_decisions, test::csvDataRows(dir / "scenario" / "decisions.csv"));
  EXPECT_EQ(test::csvDataRows(dir / "recording" / "commands.csv"),
            test::csvDataRows(dir / "scenario" / "commands.csv"));

  // 3. The recording replayed into a new filter and fault manager.
  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "replay-triplex-test"), shutdown);
  std::vector<std::string> rows, decisions;
  int watchdog_decisions = 0;
  std::set<std::string> lanes;
  me.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) { rows.push_back(records::csvRows(s).at(0)); });
  me.subscribe<LaneSolutionPubSubType>(
      bus::topic::kLaneSolution, bus::profile::kSolutionReader,
      [&](const LaneSolution& s, const auto&) { lanes.insert(records::csvRows(s).at(0)); });
  me.subscribe<FaultDecisionPubSubType>(
      bus::topic::kFaultDecision, bus::profile::kDecisionReader,
      [&](const FaultDecision& d, const auto&) {
        const std::string row = records::csvRows(d).at(0);
        if (row.find(",watchdog,") != std::string::npos)
          ++watchdog_decisions;
        else
          decisions.push_back(row.substr(0, row.rfind(',')));  // without its run_id
      });
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  test::ChildProcess fm(navbus::test_paths::faultManagerExe(), {"-c", fm_cfg},
                        (dir / "fm.log").string());
  // The increments' readers: the filter's, the fault manager's watchdog and its parity test's.
  const auto replay = startReplay(kDomain, dir,
                                  {{"navbus/imu/increment_block", 3},
                                   {"navbus/gnss/observations_block", 2},
                                   {"navbus/gnss/fix_block", 1}});
  while (replay->running()) me.spinOnce(50ms);
  const std::string replay_log = test::readFile(dir / "replay.log");
  EXPECT_EQ(replay->wait(1s), 0) << replay_log;
  test::spinUntil(me, 60s, [&] {
    return rows.size() >= expected.size() && lanes.size() >= expected_lanes.size();
  });
  me.spinOnce(3s);  // past the watchdog's 2 s: a unit whose end was not announced is lost
  filter.signal(SIGTERM);
  fm.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  EXPECT_EQ(fm.wait(10s), 0);

  // The replay announces every unit's end (it disposes each sensor's instance; it ended only
  // unit 3's before, and units 1 and 2 went LOST 2 s after it), and the fault manager takes it
  // from whichever of its readers sees it (its watchdog's best-effort reader did not, and all
  // three units went LOST in 4 of 4 runs): no watchdog decision at the end.
  EXPECT_EQ(watchdog_decisions, 0);
  const std::string fm_log = test::readFile(dir / "fm.log");
  const std::string filter_log = test::readFile(dir / "filter.log");
  for (int unit = 1; unit <= 3; ++unit)
    EXPECT_NE(filter_log.find("navbus/imu/increment id " + std::to_string(unit) + " ended"),
              std::string::npos)
        << "unit " << unit << "'s end announced to the filter's (reliable) reader" << filter_log;
  ASSERT_EQ(rows.size(), expected.size()) << test::readFile(dir / "filter.log");
  const std::size_t differing = test::countDiffering(rows, expected);
  EXPECT_EQ(differing, 0u) << test::readFile(dir / "filter.log");
  std::size_t lanes_differing = 0;
  for (const std::string& row : expected_lanes) lanes_differing += lanes.count(row) == 0 ? 1 : 0;
  EXPECT_EQ(lanes.size(), expected_lanes.size());
  EXPECT_EQ(lanes_differing, 0u);
  std::vector<std::string> expected_without_run;
  for (const std::string& row : expected_decisions)
    expected_without_run.push_back(row.substr(0, row.rfind(',')));
  EXPECT_EQ(decisions, expected_without_run) << fm_log;
  std::printf(
      "triplex recording: offline from the recording = from the scenario; replayed over the bus: "
      "%zu solutions (%zu differ), %zu lane solutions (%zu differ), decisions %s; watchdog "
      "decisions at the end %d\n",
      rows.size(), differing, lanes.size(), lanes_differing,
      decisions == expected_without_run ? "equal" : "DIFFERENT", watchdog_decisions);
  test::cleanSharedMemory();
  if (!HasFailure()) std::filesystem::remove_all(dir);  // kept to look into
}
