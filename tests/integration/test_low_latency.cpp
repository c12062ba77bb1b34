// The low-latency output over the bus: navbus-filter with config/filter_latency.yaml, fed by
// `navbus latency imu` (a real IMU writer and real subscribers of both solution topics): every
// increment gets its low-latency output, the deterministic solutions keep coming, and the
// filter counts what it published. Domain 98.
#include <gtest/gtest.h>

#include <cstring>
#include <sstream>

#include "harness.hpp"
#include "test_paths.hpp"

using namespace navbus;

TEST(LowLatencyBus, EveryIncrementGetsItsOutputOverTheBus) {
  constexpr int kDomain = 98;
  constexpr int kSamples = 400, kWarmup = 40;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("low-latency");
  const std::string cfg = test::writeFile(
      dir / "filter.yaml",
      test::readFile(std::string(navbus::test_paths::configDir()) + "/filter_latency.yaml") +
          "domain_id: " + std::to_string(kDomain) + "\n");
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", cfg},
                            (dir / "filter.log").string());
  const std::string csv = (dir / "latency.csv").string();
  // A passive observer on the same bus: IMU source time stamps -> outputs received. It stops
  // after kObserved outputs past its warm-up (fewer than the tool sends: the first increments
  // come before the filter's first solution, the anchor of the outputs).
  constexpr int kObserved = kSamples / 2;
  test::ChildProcess observer(
      navbus::test_paths::toolExe(),
      {"-d", std::to_string(kDomain), "latency", "observe", "--samples", std::to_string(kObserved),
       "--warmup", std::to_string(kWarmup), "--duration", "60"},
      (dir / "observe.log").string());
  test::ChildProcess tool(
      navbus::test_paths::toolExe(),
      {"-d", std::to_string(kDomain), "latency", "imu", "--samples", std::to_string(kSamples),
       "--warmup", std::to_string(kWarmup), "--csv", csv},
      (dir / "tool.log").string());
  const auto rc = tool.wait(std::chrono::seconds(60));
  ASSERT_TRUE(rc.has_value()) << test::readFile(dir / "tool.log");
  EXPECT_EQ(*rc, 0) << test::readFile(dir / "tool.log");
  std::printf("%s", test::readFile(dir / "tool.log").c_str());

  // Every timed increment: its low-latency output received; a deterministic solution for
  // every tenth (10 Hz solutions from 200 Hz increments), each later than the write.
  std::istringstream rows(test::readFile(csv));
  std::string line;
  std::getline(rows, line);
  EXPECT_EQ(line, "seq,low_latency_ns,solution_ns");
  int outputs = 0, solutions = 0, timed = 0;
  while (std::getline(rows, line)) {
    ++timed;
    long long seq = 0, fast = 0, det = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lld,%lld,%lld", &seq, &fast, &det), 3) << line;
    outputs += fast > 0 ? 1 : 0;
    solutions += det > 0 ? 1 : 0;
  }
  EXPECT_EQ(timed, kSamples);
  EXPECT_EQ(outputs, kSamples);
  EXPECT_GE(solutions, kSamples / 20 - 2);

  // The observer timed the outputs whose increment it saw (its IMU reader is best effort):
  // at least 90 % of them, and some deterministic solutions.
  const auto observed = observer.wait(std::chrono::seconds(30));
  ASSERT_TRUE(observed.has_value()) << test::readFile(dir / "observe.log");
  EXPECT_EQ(*observed, 0) << test::readFile(dir / "observe.log");
  const std::string observe_log = test::readFile(dir / "observe.log");
  std::printf("%s", observe_log.c_str());
  const auto fast_at = observe_log.find("low-latency output");
  const auto det_at = observe_log.find("deterministic solution");
  ASSERT_NE(fast_at, std::string::npos) << observe_log;
  ASSERT_NE(det_at, std::string::npos) << observe_log;
  const auto count_after = [&](std::size_t at) {
    return std::atoi(observe_log.c_str() + observe_log.find('(', at) + 1);
  };
  EXPECT_GE(count_after(fast_at), kObserved * 9 / 10) << observe_log;
  EXPECT_GE(count_after(det_at), 1) << observe_log;

  filter.signal(SIGINT);
  ASSERT_TRUE(filter.wait(std::chrono::seconds(20)).has_value());
  const std::string log = test::readFile(dir / "filter.log");
  // The filter's count: every increment after its first solution (the first anchor), none
  // refused by the predictor.
  const auto at = log.find("low-latency outputs ");
  ASSERT_NE(at, std::string::npos) << log;
  const int published = std::atoi(log.c_str() + at + std::strlen("low-latency outputs "));
  EXPECT_GE(published, kSamples);
  EXPECT_LE(published, kSamples + kWarmup);
  EXPECT_NE(log.find("(increments not after the anchor 0, out of order 0, gaps 0, beyond the "
                     "buffer 0)"),
            std::string::npos)
      << log;
  test::cleanSharedMemory();
}

// Saturation throughput over the bus: `navbus latency flood` writes as fast as the reliable
// sensor writer takes samples, `navbus latency sink` (another process) takes them. The sink
// counts every sample and no sequence gap, and sees the flood end its stream. Domain 99.
TEST(LatencyFlood, ReliableFloodReachesTheSinkWithoutLoss) {
  constexpr int kDomain = 99;
  constexpr int kSamples = 20000, kWarmup = 1000;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("latency-flood");
  test::ChildProcess sink(navbus::test_paths::toolExe(),
                          {"-d", std::to_string(kDomain), "latency", "sink", "--duration", "60"},
                          (dir / "sink.log").string());
  test::ChildProcess flood(navbus::test_paths::toolExe(),
                           {"-d", std::to_string(kDomain), "latency", "flood", "--samples",
                            std::to_string(kSamples), "--warmup", std::to_string(kWarmup)},
                           (dir / "flood.log").string());
  const auto flood_rc = flood.wait(std::chrono::seconds(60));
  ASSERT_TRUE(flood_rc.has_value()) << test::readFile(dir / "flood.log");
  EXPECT_EQ(*flood_rc, 0) << test::readFile(dir / "flood.log");
  const auto sink_rc = sink.wait(std::chrono::seconds(30));
  ASSERT_TRUE(sink_rc.has_value()) << test::readFile(dir / "sink.log");
  EXPECT_EQ(*sink_rc, 0) << test::readFile(dir / "sink.log");
  const std::string flood_log = test::readFile(dir / "flood.log");
  const std::string sink_log = test::readFile(dir / "sink.log");
  std::printf("%s%s", flood_log.c_str(), sink_log.c_str());
  EXPECT_NE(flood_log.find("20000 samples of 88 bytes written and acknowledged"),
            std::string::npos);
  EXPECT_NE(sink_log.find("took 21000 samples"), std::string::npos);
  EXPECT_NE(sink_log.find("missing 0 (sequence gaps), out of order 0; the flood ended its stream"),
            std::string::npos);
  test::cleanSharedMemory();
}
