// The filter pipeline's command rules without a bus: a durable command from an earlier run
// (about data before this run's first input) is refused as stale, never re-applied; a command
// about this run's data acts.
#include <gtest/gtest.h>

#include "filter_config.hpp"
#include "filter_pipeline.hpp"
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
