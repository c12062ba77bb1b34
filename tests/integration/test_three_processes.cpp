// The three participants as separate processes on one domain: solution rate, a stream-loss
// decision when the simulator dies, the filter's mode change, and recovery on restart.
#include <cmath>

#include <gtest/gtest.h>
#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "harness.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {
constexpr int kDomain = 71;

struct Observed {
  std::vector<std::pair<Clock::time_point, NavigationSolution>> solutions;
  std::vector<std::pair<Clock::time_point, FaultDecision>> decisions;
};

bool hasDecision(const Observed& o, FaultSource src, FaultEvent event, std::size_t from = 0) {
  for (std::size_t i = from; i < o.decisions.size(); ++i) {
    const auto& d = o.decisions[i].second;
    if (d.source() == src && d.event() == event) return true;
  }
  return false;
}
}  // namespace

TEST(ThreeProcesses, SolutionRateStreamLossDecisionModeChangeAndRecovery) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("three");
  const std::string sim_cfg = test::writeFile(
      dir / "sim.yaml",
      "domain_id: " + std::to_string(kDomain) +
          "\nseed: 3\n"
          "timing: {start: now, duration_s: 0, pacing: realtime, wait_for_readers_s: 20,\n"
          "         min_readers: {imu: 3, raw_imu: 1, gnss: 2, star_tracker: 2}}\n"
          "imu: {accel_noise_ug_per_sqrthz: 10, gyro_arw_deg_per_sqrth: 0.005}\n");
  const std::string filter_cfg = test::writeFile(dir / "filter.yaml", test::filterConfig(kDomain));
  const std::string fm_cfg =
      test::writeFile(dir / "fm.yaml", "domain_id: " + std::to_string(kDomain) + "\n");

  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "three-process-test"), shutdown);
  Observed seen;
  me.subscribe<NavigationSolutionPubSubType>(bus::topic::kNavSolution,
                                             bus::profile::kSolutionReader,
                                             [&](const NavigationSolution& s, const auto&) {
                                               seen.solutions.emplace_back(Clock::now(), s);
                                             });
  me.subscribe<FaultDecisionPubSubType>(
      bus::topic::kFaultDecision, bus::profile::kDecisionReader,
      [&](const FaultDecision& d, const auto&) { seen.decisions.emplace_back(Clock::now(), d); });
  // The test also reads IMU increments, so the simulator waits for 3 IMU readers.
  std::size_t imu_seen = 0;
  me.subscribe<ImuIncrementPubSubType>(bus::topic::kImuIncrement, bus::profile::kSensorReader,
                                       [&](const auto&, const auto&) { ++imu_seen; });

  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  test::ChildProcess fm(navbus::test_paths::faultManagerExe(), {"-c", fm_cfg},
                        (dir / "fm.log").string());
  auto sim = std::make_unique<test::ChildProcess>(navbus::test_paths::sensorSimExe(),
                                                  std::vector<std::string>{"-c", sim_cfg},
                                                  (dir / "sim1.log").string());

  // Given the three participants running, solutions arrive at the configured 10 Hz.
  ASSERT_TRUE(test::spinUntil(me, 30s, [&] { return seen.solutions.size() >= 5; }))
      << test::readFile(dir / "filter.log") << test::readFile(dir / "sim1.log");
  const std::size_t n0 = seen.solutions.size();
  const auto t0 = Clock::now();
  test::spinUntil(me, 4s, [] { return false; });
  const double wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  const std::size_t n = seen.solutions.size() - n0;
  const double rate_hz = static_cast<double>(n) / wall_s;
  const auto& last = seen.solutions.back().second;
  const auto& first = seen.solutions[n0].second;
  const double data_span_s = 1e-9 * static_cast<double>(last.time_gps_ns() - first.time_gps_ns());
  std::printf(
      "solution rate: %.2f Hz over %.2f s of wall time (%zu solutions); solution times step %.3f "
      "s\n",
      rate_hz, wall_s, n, data_span_s / static_cast<double>(n - 1));
  EXPECT_NEAR(rate_hz, 10.0, 1.0);
  EXPECT_NEAR(data_span_s / static_cast<double>(n - 1), 0.1,
              1e-9);  // exactly one per 100 ms of GPS time
  for (const auto& [when, s] : seen.solutions) {
    EXPECT_EQ(s.mode(), MODE_INERTIAL_ONLY);
    EXPECT_TRUE(std::isfinite(s.latitude_rad()) && std::isfinite(s.height_m()));
  }
  EXPECT_FALSE(hasDecision(seen, SOURCE_IMU_STREAM, EVENT_STREAM_LOST));

  // When the simulator dies without a goodbye (SIGKILL),
  const std::size_t decisions_before = seen.decisions.size();
  sim->signal(SIGKILL);
  const auto killed_at = Clock::now();
  // then the fault manager decides the IMU stream is lost within its deadline, and the filter
  // publishes a solution in mode INERTIAL_LOST with the fault flag set.
  ASSERT_TRUE(test::spinUntil(me, 5s, [&] {
    return hasDecision(seen, SOURCE_IMU_STREAM, EVENT_STREAM_LOST, decisions_before);
  })) << test::readFile(dir / "fm.log");
  double decision_latency_s = 0;
  for (const auto& [when, d] : seen.decisions) {
    if (d.source() == SOURCE_IMU_STREAM && d.event() == EVENT_STREAM_LOST) {
      decision_latency_s = std::chrono::duration<double>(when - killed_at).count();
      EXPECT_EQ(d.detector().to_string(), "watchdog");
      EXPECT_DOUBLE_EQ(d.threshold(), 0.25);  // the watchdog reader's requested deadline
      break;
    }
  }
  ASSERT_TRUE(test::spinUntil(me, 5s, [&] {
    const auto& s = seen.solutions.back().second;
    return s.mode() == MODE_INERTIAL_LOST && (s.active_fault_flags() & FAULT_IMU_STREAM_LOST) != 0;
  })) << test::readFile(dir / "filter.log");
  const double mode_latency_s =
      std::chrono::duration<double>(seen.solutions.back().first - killed_at).count();
  std::printf(
      "IMU stream lost decision %.3f s after SIGKILL (deadline 0.25 s); INERTIAL_LOST solution "
      "after %.3f s\n",
      decision_latency_s, mode_latency_s);
  EXPECT_LT(decision_latency_s, 1.0);
  // The held solution keeps coming (at least the 1 Hz the solution deadline promises).
  const std::size_t held_before = seen.solutions.size();
  test::spinUntil(me, 1500ms, [] { return false; });
  EXPECT_GE(seen.solutions.size() - held_before, 5u);

  // When the simulator is started again,
  const std::size_t decisions_mid = seen.decisions.size();
  sim = std::make_unique<test::ChildProcess>(navbus::test_paths::sensorSimExe(),
                                             std::vector<std::string>{"-c", sim_cfg},
                                             (dir / "sim2.log").string());
  // then the stream is declared restored and the filter is back to inertial navigation with
  // the stream-lost flag cleared.
  ASSERT_TRUE(test::spinUntil(
      me, 30s,
      [&] {
        return hasDecision(seen, SOURCE_IMU_STREAM, EVENT_STREAM_RESTORED, decisions_mid) &&
               seen.solutions.back().second.mode() == MODE_INERTIAL_ONLY &&
               (seen.solutions.back().second.active_fault_flags() & FAULT_IMU_STREAM_LOST) == 0;
      }))
      << test::readFile(dir / "filter.log") << test::readFile(dir / "sim2.log");
  // The gap is flagged: nothing was propagated across it.
  EXPECT_NE(seen.solutions.back().second.active_fault_flags() & FAULT_IMU_GAP, 0u);

  sim->signal(SIGTERM);
  EXPECT_EQ(sim->wait(10s), 0);
  filter.signal(SIGTERM);
  fm.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  EXPECT_EQ(fm.wait(10s), 0);
  std::printf("samples seen by the test: %zu IMU increments, %zu solutions, %zu decisions\n",
              imu_seen, seen.solutions.size(), seen.decisions.size());
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}
