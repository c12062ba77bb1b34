// Crash and restart (issue 10, item 8): the three participants on the shared-memory profile;
// in each round one of them, in turn, is killed with SIGKILL at a random moment and started
// again. Checked in every round, through a test participant on the bus:
// - the survivors publish what they know: a dead simulator -> the fault manager's IMU
//   stream-lost decision; a dead filter -> the fault manager still reports its health; a dead
//   fault manager -> the filter's solutions carry FAULT_NO_FAULT_MONITOR;
// - the restarted participant resumes within 1 s of its first input: a restarted simulator
//   replays its scenario from its fixed start time, and the filter's first solution of the new
//   run (sequence 1) follows the first increment of the new run; a restarted filter or fault
//   manager reports in its health how long after its first input it was RUNNING
//   (Health::resume_ns, published at once), the filter's solutions reach the test and, after a
//   fault manager's restart, the filter's flag clears. The time from a process's start to its
//   first output (process start and discovery included) is printed beside it;
// - at the end, after a clean stop, no data segment of a dead participant is left in /dev/shm
//   (ports are reused by number and left to Fast DDS: bus/shared_memory.hpp).
// Rounds per participant: NAVBUS_KILL_ROUNDS (default 2 in CI; the target is 50).
// Participant profile: NAVBUS_KILL_PROFILE (default UDP loopback; navbus_participant_shm for
// the shared-memory transport). The resume times are printed against the 1 s target and
// asserted within 10 s, a bound a busy CI machine keeps.
// A second test kills a shared-memory participant and checks that a live one reclaims what it
// left in /dev/shm.
#include <algorithm>
#include <cstdlib>
#include <random>

#include <gtest/gtest.h>
#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/HealthPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "harness.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

constexpr int kDomain = 95;
std::string profileUnderTest() {
  const char* env = std::getenv("NAVBUS_KILL_PROFILE");
  return env != nullptr ? env : bus::profile::kParticipantLoopback;
}

double msSince(Clock::time_point t0, Clock::time_point t1) {
  return std::chrono::duration<double, std::milli>(t1 - t0).count();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, rank == 0 ? 0 : rank - 1)];
}

/// What the test participant has seen, with arrival times.
struct Seen {
  std::uint64_t last_solution_seq{0};
  std::optional<Clock::time_point> new_run_at;    ///< a solution with seq 1 after a mark
  std::optional<Clock::time_point> solution_at;   ///< any solution after a mark
  std::optional<Clock::time_point> unflagged_at;  ///< a solution without the monitor flag
  std::optional<Clock::time_point> flagged_at;    ///< a solution with the monitor flag
  std::optional<Clock::time_point> imu_at;        ///< an increment after a mark
  std::optional<Clock::time_point> fm_health_at;  ///< the fault manager's health after a mark
  std::optional<Clock::time_point> imu_lost_at;   ///< an IMU stream-lost decision after a mark
  /// Health::resume_ns of the first processing report after a mark [ms], per participant.
  std::optional<double> filter_resume_ms, fm_resume_ms;
  void mark() {
    const std::uint64_t seq = last_solution_seq;
    *this = Seen();
    last_solution_seq = seq;
  }
};

struct Spawner {
  std::filesystem::path dir;
  std::string sim_cfg, filter_cfg, fm_cfg;
  int generation{0};
  std::unique_ptr<test::ChildProcess> start(int which) {
    static const char* names[] = {"sim", "filter", "fm"};
    const std::string log =
        (dir / (std::string(names[which]) + std::to_string(++generation) + ".log")).string();
    const std::vector<std::string> args{"-c",
                                        which == 0   ? sim_cfg
                                        : which == 1 ? filter_cfg
                                                     : fm_cfg,
                                        "--profile", profileUnderTest()};
    const char* exe = which == 0   ? navbus::test_paths::sensorSimExe()
                      : which == 1 ? navbus::test_paths::filterExe()
                                   : navbus::test_paths::faultManagerExe();
    return std::make_unique<test::ChildProcess>(exe, args, log);
  }
};

int roundsPerParticipant() {
  const char* env = std::getenv("NAVBUS_KILL_ROUNDS");
  return env != nullptr ? std::max(1, std::atoi(env)) : 2;
}

/// Prints what dead Fast DDS participants left in /dev/shm; returns the data segments' bytes.
std::uint64_t printDeadParticipantsShm(const char* what) {
  const std::uint64_t segments = bus::zombieSharedMemoryBytes();
  std::printf("shared memory %s: data segments %llu bytes, ports %llu bytes\n", what,
              static_cast<unsigned long long>(segments),
              static_cast<unsigned long long>(bus::zombieSharedMemoryBytes("/dev/shm", true)));
  return segments;
}

/// The three participants' configuration files of a kill loop, in `dir`.
struct KillSetup {
  std::string sim, filter, fault_manager;
};

/// The simulator's default vehicle with one IMU, the filter waiting for the fault manager.
KillSetup oneImu(const std::filesystem::path& dir, int domain) {
  const std::string dom = "domain_id: " + std::to_string(domain) + "\n";
  return {test::writeFile(dir / "sim.yaml",
                          dom + "seed: 3\n"
                                "timing: {start: '1400000000000000000', duration_s: 0, "
                                "pacing: realtime, "
                                "wait_for_readers_s: 20,\n"
                                "  min_readers: {imu: 3, raw_imu: 1, gnss: 2, star_tracker: 2}}\n"
                                "imu: {accel_noise_ug_per_sqrthz: 10, "
                                "gyro_arw_deg_per_sqrth: 0.005}\n"),
          test::writeFile(dir / "filter.yaml", test::filterConfig(domain) +
                                                   "fault_monitor: {participant: "
                                                   "navbus-fault-manager, timeout_s: 1.0}\n"),
          test::writeFile(dir / "fm.yaml", dom)};
}

/// The triplex aircraft: three IMUs, the filter's three lanes (waiting for the parity test from
/// the first sample, 1 s at most: a dead fault manager costs the output one such budget) and
/// the fault manager's parity test.
KillSetup triplex(const std::filesystem::path& dir, int domain) {
  const std::string src = navbus::test_paths::sourceDir();
  const std::string dom = "domain_id: " + std::to_string(domain) + "\n";
  return {
      test::writeFile(dir / "sim.yaml",
                      "extends: " + src + "/sim/scenarios/seed000_triplex.yaml\n" + dom +
                          "timing: {duration_s: 0, pacing: realtime, wait_for_readers_s: 20}\n"),
      test::writeFile(dir / "filter.yaml", "extends: " + src + "/config/filter_triplex.yaml\n" +
                                               dom +
                                               "fault_monitor: {participant: "
                                               "navbus-fault-manager, timeout_s: 1.0, "
                                               "judgement_wait_s: 1.0, judged_from_start: true}\n"),
      test::writeFile(dir / "fm.yaml",
                      "extends: " + src + "/config/fault_manager_triplex.yaml\n" + dom)};
}

void killLoop(int domain, const std::string& name,
              KillSetup (*setup)(const std::filesystem::path&, int)) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir(name);
  const KillSetup files = setup(dir, domain);
  Spawner spawn{dir, files.sim, files.filter, files.fault_manager};

  bus::ShutdownSignal shutdown;
  auto options = test::testParticipant(domain, name + "-test");
  options.dds.participant_profile = profileUnderTest();
  bus::Participant me(options, shutdown);
  Seen seen;
  const auto now = [] { return Clock::now(); };
  me.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) {
        if (s.seq() == 1 && !seen.new_run_at) seen.new_run_at = now();
        if (!seen.solution_at) seen.solution_at = now();
        const bool flagged = (s.active_fault_flags() & FAULT_NO_FAULT_MONITOR) != 0;
        if (flagged && !seen.flagged_at) seen.flagged_at = now();
        if (!flagged && !seen.unflagged_at) seen.unflagged_at = now();
        seen.last_solution_seq = s.seq();
      });
  me.subscribe<ImuIncrementPubSubType>(bus::topic::kImuIncrement, bus::profile::kSensorReader,
                                       [&](const auto&, const auto&) {
                                         if (!seen.imu_at) seen.imu_at = now();
                                       });
  me.subscribe<HealthPubSubType>(
      bus::topic::kHealth, bus::profile::kHealthReader, [&](const Health& h, const auto&) {
        const std::string who = h.participant().to_string();
        const bool processing = h.state() == STATE_RUNNING || h.state() == STATE_DEGRADED;
        if (processing && h.resume_ns() > 0 &&
            (who == "navbus-filter" || who == "navbus-fault-manager")) {
          auto& resume = who == "navbus-filter" ? seen.filter_resume_ms : seen.fm_resume_ms;
          if (!resume) resume = static_cast<double>(h.resume_ns()) * 1e-6;
        }
        if (who != "navbus-fault-manager" || seen.fm_health_at) return;
        // Monitoring: it has taken IMU increments.
        for (const auto& in : h.inputs())
          if (in.topic().to_string() == bus::topic::kImuIncrement && in.accepted() > 0)
            seen.fm_health_at = now();
      });
  me.subscribe<FaultDecisionPubSubType>(
      bus::topic::kFaultDecision, bus::profile::kDecisionReader,
      [&](const FaultDecision& d, const auto&) {
        if (d.source() == SOURCE_IMU_STREAM && d.event() == EVENT_STREAM_LOST && !seen.imu_lost_at)
          seen.imu_lost_at = now();
      });

  std::unique_ptr<test::ChildProcess> procs[3] = {nullptr, spawn.start(1), spawn.start(2)};
  procs[0] = spawn.start(0);
  ASSERT_TRUE(test::spinUntil(me, 30s, [&] { return seen.unflagged_at.has_value(); }))
      << test::readFile(dir / "filter2.log");

  const int rounds = 3 * roundsPerParticipant();
  // Seeded: a failure is replayed with the same kill delays (NAVBUS_KILL_LOOP_SEED picks
  // another sequence).
  const char* seed_env = std::getenv("NAVBUS_KILL_LOOP_SEED");
  const unsigned seed =
      seed_env != nullptr ? static_cast<unsigned>(std::strtoul(seed_env, nullptr, 10)) : 20261127u;
  std::printf("kill loop: %d rounds, seed %u (NAVBUS_KILL_LOOP_SEED)\n", rounds, seed);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> delay_ms(200, 1500);
  std::vector<double> resume_ms[3];
  std::vector<double> start_to_output_ms[3];  // filter and fault manager, from their start
  std::uint64_t max_zombie_bytes = 0;
  for (int r = 0; r < rounds; ++r) {
    const int victim = r % 3;
    test::spinUntil(me, std::chrono::milliseconds(delay_ms(rng)), [] { return false; });
    procs[victim]->signal(SIGKILL);
    procs[victim]->wait(5s);
    seen.mark();
    // The survivors publish what they know.
    if (victim == 0) {
      EXPECT_TRUE(test::spinUntil(me, 3s, [&] { return seen.imu_lost_at.has_value(); }))
          << "round " << r << ": no IMU stream-lost decision after the simulator died";
    } else if (victim == 1) {
      EXPECT_TRUE(test::spinUntil(me, 3s, [&] { return seen.fm_health_at.has_value(); }))
          << "round " << r << ": the fault manager fell silent with the filter";
    } else {
      EXPECT_TRUE(test::spinUntil(me, 3s, [&] { return seen.flagged_at.has_value(); }))
          << "round " << r << ": no FAULT_NO_FAULT_MONITOR after the fault manager died";
    }
    max_zombie_bytes = std::max(max_zombie_bytes, bus::zombieSharedMemoryBytes());
    seen.mark();
    const auto restarted_at = now();
    procs[victim] = spawn.start(victim);
    double resume = -1;
    if (victim == 0) {
      // Resumed: the filter's first solution of the new run after the new run's first input.
      if (test::spinUntil(me, 10s, [&] { return seen.new_run_at && seen.imu_at; }))
        // <= 0 when the test's own reader got the first increment after the filter did.
        resume = std::max(0.0, msSince(*seen.imu_at, *seen.new_run_at));
    } else if (victim == 1) {
      // Resumed: it says so itself (first input -> RUNNING, announced at once); its solutions
      // reach us.
      if (test::spinUntil(me, 10s, [&] { return seen.solution_at && seen.filter_resume_ms; })) {
        resume = *seen.filter_resume_ms;
        start_to_output_ms[1].push_back(msSince(restarted_at, *seen.solution_at));
      }
    } else {
      if (test::spinUntil(me, 10s, [&] {
            return seen.fm_health_at && seen.fm_resume_ms && seen.unflagged_at;
          })) {
        resume = *seen.fm_resume_ms;
        start_to_output_ms[2].push_back(msSince(restarted_at, *seen.fm_health_at));
      }
    }
    EXPECT_GE(resume, 0.0) << "round " << r << ": participant " << victim << " did not resume";
    if (resume >= 0.0) resume_ms[victim].push_back(resume);
  }

  static const char* names[] = {
      "simulator (its first increment -> the filter's first solution of the new run)",
      "filter (its first input -> RUNNING, Health::resume_ns)",
      "fault manager (its first input -> RUNNING, Health::resume_ns)"};
  for (int v = 0; v < 3; ++v) {
    std::printf("resume of the %s: median %.0f ms, max %.0f ms over %zu restarts\n", names[v],
                percentile(resume_ms[v], 0.5), percentile(resume_ms[v], 1.0), resume_ms[v].size());
    const auto over = std::count_if(resume_ms[v].begin(), resume_ms[v].end(),
                                    [](double ms) { return ms > 1000.0; });
    std::printf("  over the 1 s target: %td of %zu\n", over, resume_ms[v].size());
    if (v > 0)
      std::printf(
          "  from its start (process start, discovery) to %s: median %.0f ms, max %.0f ms\n",
          v == 1 ? "its first solution" : "its first health report with increments taken",
          percentile(start_to_output_ms[v], 0.5), percentile(start_to_output_ms[v], 1.0));
  }
  std::printf("largest shared memory of dead participants seen after a kill: %llu bytes\n",
              static_cast<unsigned long long>(max_zombie_bytes));
  // The survivors reclaim what the dead left (every 5 s, files older than 1 s); then a clean
  // stop removes their own.
  test::spinUntil(me, 7s, [] { return false; });
  for (auto& p : procs) p->signal(SIGTERM);
  for (auto& p : procs) EXPECT_EQ(p->wait(15s), 0);
  const std::uint64_t left = printDeadParticipantsShm("left by dead participants after the loop");
  EXPECT_EQ(left, 0u);
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace

TEST(KillLoop, EachParticipantKilledAndRestartedSurvivorsReportAndNothingLeftInShm) {
  killLoop(kDomain, "kill-loop", oneImu);
}

// The same with redundant IMUs: three units, three lanes, the parity test (its judgement waited
// for from the first sample). A restarted simulator is a new run for every lane and for the
// parity test (they published and tested nothing of it before: every new time was older than
// the last one), a restarted fault manager's parity test is waited for again. Domain 101.
TEST(KillLoop, WithLanesEachParticipantKilledAndRestartedSurvivorsReport) {
  killLoop(101, "kill-loop-lanes", triplex);
}

// A participant on the shared-memory profile killed with SIGKILL leaves its segment and port
// in /dev/shm (Fast DDS removes them on a clean shutdown only); a live navbus participant
// reclaims them within its reclaim period, and its own files stay.
TEST(SharedMemory, WhatAKilledParticipantLeftIsReclaimedByALiveOne) {
  constexpr int kShmDomain = 96;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("shm-reclaim");
  const std::string filter_cfg =
      test::writeFile(dir / "filter.yaml", test::filterConfig(kShmDomain));
  bus::ShutdownSignal shutdown;
  auto options = test::testParticipant(kShmDomain, "shm-reclaim-test");
  options.dds.participant_profile = "navbus_participant_shm";
  bus::Participant me(options, shutdown);
  std::size_t health_seen = 0;
  me.subscribe<HealthPubSubType>(bus::topic::kHealth, bus::profile::kHealthReader,
                                 [&](const Health& h, const auto&) {
                                   if (h.participant().to_string() == "navbus-filter")
                                     ++health_seen;
                                 });
  {
    test::ChildProcess filter(navbus::test_paths::filterExe(),
                              {"-c", filter_cfg, "--profile", "navbus_participant_shm"},
                              (dir / "filter.log").string());
    ASSERT_TRUE(test::spinUntil(me, 20s, [&] { return health_seen > 0; }))
        << test::readFile(dir / "filter.log");
    filter.signal(SIGKILL);
    filter.wait(5s);
  }
  const std::uint64_t left = printDeadParticipantsShm("left by the killed participant");
  EXPECT_GT(left, 1'000'000u);  // its 4 MB segment at least
  const auto t0 = Clock::now();
  EXPECT_TRUE(test::spinUntil(me, bus::Participant::kShmReclaimPeriod + 3s,
                              [] { return bus::zombieSharedMemoryBytes() == 0; }));
  std::printf("reclaimed by the live participant after %.1f s\n",
              std::chrono::duration<double>(Clock::now() - t0).count());
  // The live participant still works: it hears a new participant's health.
  health_seen = 0;
  test::ChildProcess filter(navbus::test_paths::filterExe(),
                            {"-c", filter_cfg, "--profile", "navbus_participant_shm"},
                            (dir / "filter2.log").string());
  EXPECT_TRUE(test::spinUntil(me, 20s, [&] { return health_seen > 0; }));
  filter.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

// The last shared-memory participant on the host to stop removes what dead ones left, their
// ports included: a killed filter's port stays while a participant lives (its number is reused,
// bus/shared_memory.hpp), and is gone once that participant has stopped cleanly.
TEST(SharedMemory, TheLastParticipantOutLeavesNothing) {
  constexpr int kShmDomain = 97;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("shm-last-out");
  const std::string filter_cfg =
      test::writeFile(dir / "filter.yaml", test::filterConfig(kShmDomain));
  {
    bus::ShutdownSignal shutdown;
    auto options = test::testParticipant(kShmDomain, "shm-last-out-test");
    options.dds.participant_profile = "navbus_participant_shm";
    bus::Participant me(options, shutdown);
    bool health_seen = false;
    me.subscribe<HealthPubSubType>(bus::topic::kHealth, bus::profile::kHealthReader,
                                   [&](const Health& h, const auto&) {
                                     health_seen |= h.participant().to_string() == "navbus-filter";
                                   });
    test::ChildProcess filter(navbus::test_paths::filterExe(),
                              {"-c", filter_cfg, "--profile", "navbus_participant_shm"},
                              (dir / "filter.log").string());
    ASSERT_TRUE(test::spinUntil(me, 20s, [&] { return health_seen; }))
        << test::readFile(dir / "filter.log");
    filter.signal(SIGKILL);
    filter.wait(5s);
    test::spinUntil(me, 1500ms, [] { return false; });  // older than the reclaim's 1 s
    EXPECT_GT(bus::zombieSharedMemoryBytes("/dev/shm", true), 0u) << "the dead filter's port";
  }
  printDeadParticipantsShm("left after the last participant stopped");
  if (bus::sharedMemoryInUse()) {
    std::printf(
        "another shared-memory participant lives on this host (a parallel test): it is "
        "the last one out, not checked here\n");
  } else {
    EXPECT_EQ(bus::zombieSharedMemoryBytes(), 0u);
    EXPECT_EQ(bus::zombieSharedMemoryBytes("/dev/shm", true), 0u);
  }
  if (!HasFailure()) std::filesystem::remove_all(dir);
}
