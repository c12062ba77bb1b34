// --exit-when-ended (bus/stop_after_end.hpp), what the compose demo's filter and fault manager
// rely on to stop by themselves: both stop, with exit code 0, once the simulator has announced
// the end of its data, and also once it has left the bus without announcing it (killed here;
// for the fault manager's best-effort watchdog reader, a dispose lost on the way looks the
// same). Before, a participant that missed the announcement waited for ever. And the fault
// manager learns an end whose dispose it lost from the writer's health report (ENDED), where a
// writer that leaves without announcing it is still a loss.
#include <memory>

#include <gtest/gtest.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "harness.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/bus/stream_end.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace std::chrono_literals;

namespace {

/// The filter and the fault manager under --exit-when-ended, and the simulator (its timing
/// given); `sim` is started last.
struct EndingLoop {
  std::filesystem::path dir;
  std::string sim_cfg, filter_cfg, fm_cfg;

  EndingLoop(const std::string& name, int domain, const std::string& timing)
      : dir(test::scratchDir(name)) {
    const std::string d = "domain_id: " + std::to_string(domain) + "\n";
    sim_cfg = test::writeFile(
        dir / "sim.yaml", d + "seed: 3\ntiming: {start: now, wait_for_readers_s: 20, " + timing +
                              ",\n  min_readers: {imu: 2, raw_imu: 1, gnss: 2, "
                              "star_tracker: 2}}\n");
    filter_cfg = test::writeFile(dir / "filter.yaml", test::filterConfig(domain));
    fm_cfg = test::writeFile(dir / "fm.yaml", d);
  }
  std::string log(const std::string& name) const { return test::readFile(dir / name); }

  std::unique_ptr<test::ChildProcess> filter, fm, sim;
  /// The filter and the fault manager with --exit-when-ended, then the simulator.
  void start() {
    filter = std::make_unique<test::ChildProcess>(
        test_paths::filterExe(), std::vector<std::string>{"-c", filter_cfg, "--exit-when-ended"},
        (dir / "filter.log").string());
    fm = std::make_unique<test::ChildProcess>(
        test_paths::faultManagerExe(), std::vector<std::string>{"-c", fm_cfg, "--exit-when-ended"},
        (dir / "fm.log").string());
    sim = std::make_unique<test::ChildProcess>(test_paths::sensorSimExe(),
                                               std::vector<std::string>{"-c", sim_cfg},
                                               (dir / "sim.log").string());
  }
};

}  // namespace

TEST(ExitWhenEnded, BothStopOnceTheSimulatorAnnouncedTheEnd) {
  test::cleanSharedMemory();
  constexpr int kDomain = 193;
  EndingLoop loop("exit_when_ended_announced", kDomain, "duration_s: 20, pacing: fast");
  loop.start();
  ASSERT_EQ(loop.sim->wait(120s), 0) << loop.log("sim.log");
  // The grace is 2 s: 10 s is a bound a busy machine keeps.
  EXPECT_EQ(loop.filter->wait(10s), 0) << loop.log("filter.log");
  EXPECT_EQ(loop.fm->wait(10s), 0) << loop.log("fm.log");
  EXPECT_NE(loop.log("filter.log").find("the IMU stream ended; stopping"), std::string::npos);
  EXPECT_NE(loop.log("fm.log").find("the IMU stream ended; stopping"), std::string::npos);
  test::cleanSharedMemory();
}

TEST(ExitWhenEnded, BothStopOnceTheSimulatorLeftWithoutAnnouncingIt) {
  test::cleanSharedMemory();
  constexpr int kDomain = 194;
  EndingLoop loop("exit_when_ended_killed", kDomain, "duration_s: 0, pacing: realtime");
  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "exit-when-ended-test"), shutdown);
  std::size_t solutions = 0;
  me.subscribe<NavigationSolutionPubSubType>(bus::topic::kNavSolution,
                                             bus::profile::kSolutionReader,
                                             [&](const auto&, const auto&) { ++solutions; });
  loop.start();
  ASSERT_TRUE(test::spinUntil(me, 60s, [&] { return solutions >= 20; }))
      << loop.log("filter.log") << loop.log("sim.log");
  loop.sim->signal(SIGKILL);  // no dispose, no goodbye: its liveliness lapses (1 s lease)
  // Lease and grace: about 3 s; 15 s is a bound a busy machine keeps.
  EXPECT_EQ(loop.filter->wait(15s), 0) << loop.log("filter.log");
  EXPECT_EQ(loop.fm->wait(15s), 0) << loop.log("fm.log");
  const std::string left = "every IMU writer left the bus without announcing";
  EXPECT_NE(loop.log("filter.log").find(left), std::string::npos);
  EXPECT_NE(loop.log("fm.log").find(left), std::string::npos);
  test::cleanSharedMemory();
}

namespace {

/// A writer of one IMU's increments in blocks (paced by its writer, as fast pacing and the
/// replay write them) to a fault manager under --exit-when-ended, which leaves the bus without
/// disposing its stream: as the fault manager's best-effort reader sees a dispose lost on the
/// way. With `announce`, its health report says the end of its data was announced
/// (STATE_ENDED), as the simulator's and the replay's do after their disposes. Returns the fault
/// manager's log once it stopped.
std::string leaveWithoutDispose(const char* name, int domain, bool announce) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir(name);
  const std::string cfg =
      test::writeFile(dir / "fm.yaml", "domain_id: " + std::to_string(domain) + "\n");
  test::ChildProcess fm(test_paths::faultManagerExe(), {"-c", cfg, "--exit-when-ended"},
                        (dir / "fm.log").string());
  {
    bus::ShutdownSignal shutdown;
    bus::Participant sensor(test::testParticipant(domain, "imu-writer"), shutdown);
    auto blocks = sensor.createWriter<ImuIncrementBlockPubSubType>(bus::topic::kImuIncrementBlock,
                                                                   bus::profile::kSensorWriter);
    EXPECT_TRUE(test::spinUntil(sensor, 20s, [&] { return blocks.matchedReaders() >= 1; }));
    sensor.spinFor(bus::kStartSettle);
    sim::ScenarioSource src = test::testScenarioSource();
    std::uint64_t seq = 0;
    for (std::uint64_t b = 1; b <= 20; ++b) {
      ImuIncrementBlock block;
      block.sensor_id(1);
      block.seq(b);
      for (int k = 0; k < 30; ++k)
        block.increments().push_back(bus::toIdl(src.next().increment, 1, ++seq));
      EXPECT_TRUE(blocks.write(block));
      sensor.spinOnce(1ms);
    }
    if (announce) sensor.announceDataEnded();
    sensor.spinFor(bus::kEndOfStreamLinger);
    sensor.finish();
  }  // leaves the bus
  // The grace is 2 s, after the liveliness lease (1 s) at most: 15 s is a bound a busy machine
  // keeps.
  EXPECT_EQ(fm.wait(15s), 0);
  std::string log = test::readFile(dir / "fm.log");
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
  return log;
}

}  // namespace

TEST(ExitWhenEnded, TheFaultManagerTakesTheEndFromTheWritersHealthWhenTheDisposeIsLost) {
  const std::string log = leaveWithoutDispose("exit_when_ended_health", 205, true);
  EXPECT_NE(log.find("imu stream 1 ended as its writer announced"), std::string::npos) << log;
  EXPECT_NE(log.find("the IMU stream ended; stopping"), std::string::npos) << log;
  EXPECT_EQ(log.find("LOST"), std::string::npos) << log;
}

TEST(ExitWhenEnded, AWriterThatLeavesWithoutAnnouncingTheEndIsLost) {
  // Its last health report says STOPPING: it left, its data did not end as announced.
  const std::string log = leaveWithoutDispose("exit_when_ended_unannounced", 206, false);
  EXPECT_NE(log.find("imu stream 1 LOST"), std::string::npos) << log;
  EXPECT_NE(log.find("every IMU writer left the bus without announcing"), std::string::npos) << log;
  EXPECT_EQ(log.find("ended as its writer announced"), std::string::npos) << log;
}
