// The filter pipeline's command rules without a bus: a durable command from an earlier run
// (about data before this run's first input) is refused as stale, never re-applied; a command
// about this run's data acts.
#include <gtest/gtest.h>

#include "filter_config.hpp"
#include "filter_pipeline.hpp"
#include "monitor_liveness.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/sim/scenario_source.hpp"

using namespace navbus;

TEST(FilterPipelineCommands, StaleCommandOfAnEarlierRunIsRefused) {
  const auto cfg = nav_filter::parseFilterConfig(
      YAML::Load("initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}\n"
                 "inputs: {imu: {id: 1, period_s: 0.01}}\n"));
  bus::HealthCounters health("test");
  std::vector<NavigationSolution> solutions;
  nav_filter::FilterPipeline pipeline(
      cfg, health, {[&](const NavigationSolution& s) { solutions.push_back(s); }, nullptr});

  sim::ScenarioConfig src_cfg;
  src_cfg.vehicle.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  src_cfg.start_time_ns = 1'400'000'000'000'000'000;
  sim::ScenarioSource src(src_cfg);
  FilterCommand lost;  // what a fault manager said about the IMU stream in an earlier run
  lost.command_id(7);
  lost.vehicle_id(1);
  lost.kind(CMD_EXCLUDE_STREAM);
  lost.sensor(SOURCE_IMU_STREAM);
  lost.sensor_id(1);
  lost.issuer("fault-manager");
  lost.time_gps_ns(src_cfg.start_time_ns - 60'000'000'000);
  pipeline.onCommand(lost);  // durable history, delivered before any data

  std::uint64_t seq = 0;
  std::int64_t now = 0;
  for (int k = 0; k < 100; ++k) {
    pipeline.onImu(bus::toIdl(src.next().increment, 1, ++seq));
    pipeline.pump(now += 10'000'000);
  }
  ASSERT_FALSE(solutions.empty());
  for (const auto& s : solutions) EXPECT_NE(s.mode(), MODE_INERTIAL_LOST);
  EXPECT_NE(pipeline.summary().find("stale 1"), std::string::npos) << pipeline.summary();

  // The same command about this run's data acts.
  lost.command_id(8);
  lost.time_gps_ns(static_cast<std::uint64_t>(solutions.back().time_gps_ns()));
  pipeline.onCommand(lost);
  EXPECT_EQ(solutions.back().mode(), MODE_INERTIAL_LOST);
  EXPECT_NE(pipeline.summary().find("commands applied 1 refused 1"), std::string::npos)
      << pipeline.summary();
  // ... and in the health of the command topic.
  const bus::StreamCounters* commands = health.find(bus::topic::kFilterCommand);
  ASSERT_NE(commands, nullptr);
  EXPECT_EQ(commands->accepted, 1u);
  EXPECT_EQ(commands->rejected.at(REJECT_STALE), 1u);
}

namespace {

nav_filter::FilterConfig imuOnlyConfig() {
  return nav_filter::parseFilterConfig(
      YAML::Load("initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}\n"
                 "inputs: {imu: {id: 1, period_s: 0.01}}\n"));
}

sim::ScenarioConfig sourceConfig() {
  sim::ScenarioConfig c;
  c.vehicle.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  c.start_time_ns = 1'400'000'000'000'000'000;
  return c;
}

}  // namespace

// A simulator restarted with its scenario starting at a fixed time sends the same times
// again, with its sequence restarting. The filter recognises the restart once the samples
// after the first continue from it, and starts over: its solutions go on, and from then on
// they equal those of a filter that started with the new run.
TEST(FilterPipelineRestart, SourceRestartingAtAnEarlierTimeStartsANewRun) {
  const auto cfg = imuOnlyConfig();
  bus::HealthCounters health("test");
  std::vector<NavigationSolution> solutions;
  nav_filter::FilterPipeline pipeline(
      cfg, health, {[&](const NavigationSolution& s) { solutions.push_back(s); }, nullptr});
  std::int64_t now = 0;
  auto feed = [&](nav_filter::FilterPipeline& p, sim::ScenarioSource& src, std::uint64_t from_seq,
                  int n, int skip = 0) {
    for (int k = 0; k < n; ++k) {
      const auto inc = bus::toIdl(src.next().increment, 1, from_seq + k);
      if (k >= skip) p.onImu(inc);
      p.pump(now += 10'000'000);
    }
  };
  sim::ScenarioSource first(sourceConfig());
  feed(pipeline, first, 1, 300);
  const std::size_t first_run = solutions.size();
  ASSERT_GT(first_run, 0u);

  sim::ScenarioSource restarted(sourceConfig());
  feed(pipeline, restarted, 1, 300);
  const bus::StreamCounters& imu = *health.find(bus::topic::kImuIncrement);
  EXPECT_EQ(imu.source_restarts, 1u);
  const int confirmations = cfg.time_jump.confirmations;
  EXPECT_EQ(imu.rejected.at(REJECT_TIME_NOT_MONOTONIC),
            static_cast<std::uint64_t>(confirmations - 1));
  EXPECT_EQ(pipeline.newRuns(), 1u);
  ASSERT_GT(solutions.size(), first_run + 10);
  const NavigationSolution& restart_first = solutions[first_run];
  EXPECT_EQ(restart_first.seq(), 1u);  // a new run for the subscribers too
  EXPECT_LT(restart_first.time_gps_ns(), solutions[first_run - 1].time_gps_ns());

  // A filter that started with the new run's first accepted sample gives the same solutions.
  bus::HealthCounters fresh_health("fresh");
  std::vector<NavigationSolution> fresh;
  nav_filter::FilterPipeline reference(
      cfg, fresh_health, {[&](const NavigationSolution& s) { fresh.push_back(s); }, nullptr});
  sim::ScenarioSource again(sourceConfig());
  feed(reference, again, 1, 300, confirmations - 1);
  ASSERT_EQ(fresh.size(), solutions.size() - first_run);
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    const auto& a = fresh[i];
    const auto& b = solutions[first_run + i];
    EXPECT_EQ(a.time_gps_ns(), b.time_gps_ns());
    EXPECT_EQ(a.latitude_rad(), b.latitude_rad());
    EXPECT_EQ(a.vel_ned_mps(), b.vel_ned_mps());
    EXPECT_EQ(a.q_b_to_n(), b.q_b_to_n());
  }
  EXPECT_NE(pipeline.summary().find("new runs after a source restart 1"), std::string::npos)
      << pipeline.summary();
}

TEST(FaultMonitorLiveness, AliveWhileReportsComeWithinTheTimeoutAndAtStart) {
  nav_filter::MonitorLiveness m(3'000'000'000, 10'000'000'000);
  EXPECT_TRUE(m.alive(12'000'000'000));   // not reported yet, but within the start grace
  EXPECT_FALSE(m.alive(13'000'000'001));  // never came
  m.onReport(14'000'000'000);
  EXPECT_TRUE(m.alive(17'000'000'000));
  EXPECT_FALSE(m.alive(17'000'000'001));
  EXPECT_EQ(m.reports(), 1u);
}

TEST(FaultMonitorLiveness, SolutionsAreFlaggedWhileNoMonitorIsAlive) {
  const auto cfg = imuOnlyConfig();
  bus::HealthCounters health("test");
  std::vector<NavigationSolution> solutions;
  nav_filter::FilterPipeline pipeline(
      cfg, health, {[&](const NavigationSolution& s) { solutions.push_back(s); }, nullptr});
  sim::ScenarioSource src(sourceConfig());
  std::uint64_t seq = 0;
  std::int64_t now = 0;
  auto run = [&](int n) {
    const std::size_t before = solutions.size();
    for (int k = 0; k < n; ++k) {
      pipeline.onImu(bus::toIdl(src.next().increment, 1, ++seq));
      pipeline.pump(now += 10'000'000);
    }
    return std::vector<NavigationSolution>(solutions.begin() + static_cast<std::ptrdiff_t>(before),
                                           solutions.end());
  };
  for (const auto& s : run(50)) EXPECT_EQ(s.active_fault_flags() & FAULT_NO_FAULT_MONITOR, 0u);
  pipeline.setFaultMonitorAlive(false);
  EXPECT_TRUE(pipeline.degraded());
  const auto without = run(50);
  ASSERT_FALSE(without.empty());
  for (const auto& s : without) EXPECT_NE(s.active_fault_flags() & FAULT_NO_FAULT_MONITOR, 0u);
  pipeline.setFaultMonitorAlive(true);
  for (const auto& s : run(50)) EXPECT_EQ(s.active_fault_flags() & FAULT_NO_FAULT_MONITOR, 0u);
  EXPECT_FALSE(pipeline.degraded());
  EXPECT_NE(pipeline.summary().find("fault monitor found not alive 1 time(s)"), std::string::npos)
      << pipeline.summary();
}
