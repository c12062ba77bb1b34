// The filter pipeline's command rules without a bus: a durable command from an earlier run
// (about data before this run's first input) is refused as stale, never re-applied; a command
// about this run's data acts.
#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/core/ins/state_layout.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/filter_pipeline.hpp"
#include "navbus/nav_filter/lane_set.hpp"
#include "navbus/nav_filter/monitor_liveness.hpp"
#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/scenario_source.hpp"
#include "test_paths.hpp"

#include <algorithm>
#include <map>
#include <variant>

#include "navbus/nav_filter/solution_flags.hpp"

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

/// Seed 001's loosely coupled filter, without a fault monitor to wait for.
nav_filter::FilterConfig seed001Filter() {
  const std::string dir = navbus::test_paths::scenarioDir();
  auto cfg = nav_filter::parseFilterConfig(
      bus::loadYamlFile(dir + "/../../config/filter_seed001_lc.yaml"));
  cfg.fault_monitor.reset();
  return cfg;
}

sensor_sim::SimConfig seed001Sim() {
  const std::string dir = navbus::test_paths::scenarioDir();
  return sensor_sim::parseSimConfig(bus::loadYamlFile(dir + "/seed001_leo.yaml"));
}

sim::ScenarioConfig sourceConfig() {
  sim::ScenarioConfig c;
  c.vehicle.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  c.start_time_ns = 1'400'000'000'000'000'000;
  return c;
}

}  // namespace

// An IMU stream declared lost while its writer is alive (the fault manager saw a silence a
// stalled process caused) only flags the solutions: increments that come are integrated. Once
// no writer is alive, the filter holds its last solution (inertial lost).
TEST(FilterPipelineCommands, ImuDeclaredLostWhileItsWriterIsAliveOnlyFlags) {
  const auto cfg = imuOnlyConfig();
  bus::HealthCounters health("test");
  std::vector<NavigationSolution> solutions;
  nav_filter::FilterPipeline pipeline(
      cfg, health, {[&](const NavigationSolution& s) { solutions.push_back(s); }, nullptr});
  sim::ScenarioSource src(sourceConfig());
  std::uint64_t seq = 0;
  std::int64_t now = 0;
  auto feed = [&](int n) {
    for (int k = 0; k < n; ++k) {
      pipeline.onImu(bus::toIdl(src.next().increment, 1, ++seq));
      pipeline.pump(now += 10'000'000);
    }
  };
  pipeline.setWritersAlive(bus::StreamKind::kImu, true, now);
  feed(100);
  FilterCommand lost;
  lost.command_id(1);
  lost.vehicle_id(1);
  lost.kind(CMD_EXCLUDE_STREAM);
  lost.sensor(SOURCE_IMU_STREAM);
  lost.sensor_id(1);
  lost.issuer("fault-manager");
  lost.time_gps_ns(static_cast<std::uint64_t>(solutions.back().time_gps_ns()));
  pipeline.onCommand(lost);
  const std::size_t before = solutions.size();
  feed(100);
  ASSERT_EQ(solutions.size(), before + 10) << "the increments are integrated";
  EXPECT_NE(solutions.back().mode(), MODE_INERTIAL_LOST);
  EXPECT_NE(solutions.back().active_fault_flags() & FAULT_IMU_STREAM_LOST, 0u) << "and flagged";

  pipeline.setWritersAlive(bus::StreamKind::kImu, false, now);
  pipeline.pump(now += cfg.sequencer_max_wait_ns / 2);
  EXPECT_NE(solutions.back().mode(), MODE_INERTIAL_LOST) << "gone, but not long enough yet";
  pipeline.pump(now += cfg.sequencer_max_wait_ns);
  EXPECT_EQ(solutions.back().mode(), MODE_INERTIAL_LOST);
}

// The fault manager's watchdog reads best effort and may miss a writer's dispose; it then
// declares the stream lost when the writer leaves (seen in a replay on a loaded machine). The
// filter received the end on its reliable reader: the command is refused and answered, the
// solutions stay unflagged. A sample after the end starts a new run that can be lost again.
TEST(FilterPipelineCommands, AStreamThatEndedAsAnnouncedIsNotLost) {
  const auto cfg = imuOnlyConfig();
  bus::HealthCounters health("test");
  std::vector<NavigationSolution> solutions;
  std::vector<FilterCommandOutcome> outcomes;
  nav_filter::FilterPipeline pipeline(
      cfg, health,
      {[&](const NavigationSolution& s) { solutions.push_back(s); }, nullptr, nullptr,
       [&](const FilterCommandOutcome& o) { outcomes.push_back(o); }});
  sim::ScenarioSource src(sourceConfig());
  std::uint64_t seq = 0;
  std::int64_t now = 0;
  auto feed = [&](int n) {
    for (int k = 0; k < n; ++k) {
      pipeline.onImu(bus::toIdl(src.next().increment, 1, ++seq));
      pipeline.pump(now += 10'000'000);
    }
  };
  pipeline.setWritersAlive(bus::StreamKind::kImu, true, now);
  feed(100);
  pipeline.onStreamEnded(bus::StreamKind::kImu, 1);
  FilterCommand lost;
  lost.command_id(1);
  lost.vehicle_id(1);
  lost.kind(CMD_EXCLUDE_STREAM);
  lost.sensor(SOURCE_IMU_STREAM);
  lost.sensor_id(1);
  lost.issuer("fault-manager");
  lost.time_gps_ns(static_cast<std::uint64_t>(solutions.back().time_gps_ns()));
  pipeline.onCommand(lost);
  ASSERT_EQ(outcomes.size(), 1u);
  EXPECT_EQ(outcomes.back().outcome(), OUTCOME_REFUSED);
  EXPECT_NE(std::string(outcomes.back().detail().c_str()).find("ended as announced"),
            std::string::npos)
      << outcomes.back().detail();
  feed(100);  // the stream starts again: a new run, whose loss holds
  for (const auto& s : solutions) EXPECT_EQ(s.active_fault_flags() & FAULT_IMU_STREAM_LOST, 0u);
  lost.command_id(2);
  lost.time_gps_ns(static_cast<std::uint64_t>(solutions.back().time_gps_ns()));
  pipeline.onCommand(lost);
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_EQ(outcomes.back().outcome(), OUTCOME_APPLIED);
  feed(20);
  EXPECT_NE(solutions.back().active_fault_flags() & FAULT_IMU_STREAM_LOST, 0u);
}

// A per-stream time offset (inputs.<stream>.time_offset_s) moves the stream's samples in the
// merge: an IMU stamped 30 ms late gives the same states 30 ms earlier (a solution per
// increment, so that both runs publish every state).
TEST(FilterPipelineGeometry, AnInputsTimeOffsetMovesItsSamples) {
  auto run = [](const std::string& imu) {
    const auto cfg = nav_filter::parseFilterConfig(
        YAML::Load("initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}\n"
                   "solution_rate_hz: 100\ninputs: {imu: " +
                   imu + "}\n"));
    bus::HealthCounters health("test");
    std::map<std::uint64_t, double> latitude_by_time;
    nav_filter::FilterPipeline pipeline(
        cfg, health,
        {[&](const NavigationSolution& s) { latitude_by_time[s.time_gps_ns()] = s.latitude_rad(); },
         nullptr});
    sim::ScenarioSource src(sourceConfig());
    std::int64_t now = 0;
    for (std::uint64_t seq = 1; seq <= 200; ++seq) {
      pipeline.onImu(bus::toIdl(src.next().increment, 1, seq));
      pipeline.pump(now += 10'000'000);
    }
    pipeline.flush(now);
    return latitude_by_time;
  };
  const auto plain = run("{id: 1, period_s: 0.01}");
  const auto shifted = run("{id: 1, period_s: 0.01, time_offset_s: -0.03}");
  ASSERT_GT(shifted.size(), 150u);
  std::size_t compared = 0;
  for (const auto& [time_ns, latitude] : shifted) {
    const auto it = plain.find(time_ns + 30'000'000);
    if (it == plain.end()) continue;
    EXPECT_EQ(it->second, latitude) << time_ns;
    ++compared;
  }
  EXPECT_GT(compared, 150u);
  EXPECT_EQ(plain.count(shifted.begin()->first), 0u) << "the shifted run starts 30 ms earlier";
}

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

// Lanes (two units, the same increments under ids 1 and 2) whose IMUs restart at an earlier time:
// the selection starts over with the lanes' new run, as one filter does (it published nothing
// of the new run before: every new time was at or before the last one selected), sequence
// numbers from 1, the same solutions as lanes that started with the new run.
TEST(FilterPipelineRestart, LanesStartTheSelectionOverWhenTheirSourcesRestart) {
  auto cfg = imuOnlyConfig();
  cfg.lanes.units = {nav_filter::LaneUnit{1}, nav_filter::LaneUnit{2}};
  const int confirmations = cfg.time_jump.confirmations;
  std::int64_t now = 0;
  auto feed = [&](nav_filter::LaneSet& lanes, sim::ScenarioSource& src, int n, int skip = 0) {
    for (int k = 0; k < n; ++k) {
      const auto increment = src.next().increment;
      if (k >= skip)
        for (std::uint32_t id : {1u, 2u})
          lanes.onImu(bus::toIdl(increment, id, static_cast<std::uint64_t>(k + 1)));
      lanes.pump(now += 10'000'000);
    }
  };
  bus::HealthCounters health("test");
  std::vector<NavigationSolution> solutions;
  nav_filter::LaneSet lanes(
      cfg, health, {{[&](const NavigationSolution& s) { solutions.push_back(s); }, nullptr}});
  sim::ScenarioSource first(sourceConfig());
  feed(lanes, first, 300);
  const std::size_t first_run = solutions.size();
  ASSERT_GT(first_run, 0u);
  sim::ScenarioSource restarted(sourceConfig());
  feed(lanes, restarted, 300);
  ASSERT_GT(solutions.size(), first_run + 10) << lanes.summary();
  EXPECT_EQ(solutions[first_run].seq(), 1u);
  EXPECT_LT(solutions[first_run].time_gps_ns(), solutions[first_run - 1].time_gps_ns());
  EXPECT_NE(lanes.summary().find("new runs after a source restart 1"), std::string::npos)
      << lanes.summary();

  bus::HealthCounters fresh_health("fresh");
  std::vector<NavigationSolution> fresh;
  nav_filter::LaneSet reference(
      cfg, fresh_health, {{[&](const NavigationSolution& s) { fresh.push_back(s); }, nullptr}});
  sim::ScenarioSource again(sourceConfig());
  feed(reference, again, 300, confirmations - 1);
  ASSERT_EQ(fresh.size(), solutions.size() - first_run);
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    EXPECT_EQ(fresh[i].time_gps_ns(), solutions[first_run + i].time_gps_ns());
    EXPECT_EQ(fresh[i].seq(), solutions[first_run + i].seq());
    EXPECT_EQ(fresh[i].latitude_rad(), solutions[first_run + i].latitude_rad());
    EXPECT_EQ(fresh[i].q_b_to_n(), solutions[first_run + i].q_b_to_n());
  }
}

// A fault manager's re-learn whose sigma exceeds the filter's compensation limit (an ambiguous
// isolation with a poorly known magnitude) is applied up to the limit and counted; a
// compensation beyond the limit is still refused.
TEST(FilterPipelineCommands, RelearnBeyondTheCompensationLimitRelearnsUpToTheLimit) {
  // Given seed 001's loosely coupled filter fed by its scenario for 2 s,
  const auto cfg = seed001Filter();
  const sensor_sim::SimConfig sim = seed001Sim();
  bus::HealthCounters health("test");
  std::vector<NavigationSolution> solutions;
  nav_filter::FilterPipeline pipeline(
      cfg, health, {[&](const NavigationSolution& s) { solutions.push_back(s); }, nullptr});
  sim::ScenarioSource src(sim.scenario);
  sensor_sim::FrameSequence seq;
  auto feed = [&](int frames) {
    for (int k = 0; k < frames; ++k) {
      const sim::SensorFrame f = src.next();
      sensor_sim::emitFrame(f, sim, seq, [&](const auto& sample) {
        using T = std::decay_t<decltype(sample)>;
        if constexpr (std::is_same_v<T, ImuIncrement>) pipeline.onImu(sample);
        if constexpr (std::is_same_v<T, GnssFix>) pipeline.onGnssFix(sample);
        if constexpr (std::is_same_v<T, StarTrackerAttitude>) pipeline.onStarTracker(sample);
        return true;
      });
      pipeline.pump(f.increment.time_ns);
    }
  };
  feed(400);
  ASSERT_FALSE(solutions.empty());
  const double limit = cfg.max_gyro_compensation_radps;
  constexpr int kGyroY = core::layout::kGyroBias.index + 1;
  const double before = pipeline.engine().covariance()(kGyroY, kGyroY);

  // when a fault manager asks it to re-learn the y gyro's bias with twice the limit as sigma,
  FilterCommand c;
  c.command_id(1);
  c.vehicle_id(cfg.vehicle_id);
  c.issuer("fault-manager");
  c.time_gps_ns(solutions.back().time_gps_ns());
  c.kind(CMD_RELEARN_BIAS);
  c.sensor(SOURCE_GYRO);
  c.axis(1);
  c.bias(0.0);
  c.bias_sigma(2.0 * limit);
  pipeline.onCommand(c);
  feed(1);  // released in data-time order (no aiding in this IMU step, no bias noise)

  // then the bias variance grows by the limit squared, the command counts as applied and the
  // clamp is counted;
  EXPECT_DOUBLE_EQ(pipeline.engine().covariance()(kGyroY, kGyroY), before + limit * limit);
  EXPECT_NE(pipeline.summary().find("commands applied 1 refused 0"), std::string::npos)
      << pipeline.summary();
  EXPECT_NE(pipeline.summary().find("re-learn sigmas clamped to the compensation limit 1"),
            std::string::npos)
      << pipeline.summary();

  // a compensation beyond the limit is still refused.
  c.command_id(2);
  c.kind(CMD_COMPENSATE_BIAS);
  pipeline.onCommand(c);
  feed(1);
  EXPECT_NE(pipeline.summary().find("commands applied 1 refused 1"), std::string::npos)
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

// The low-latency output: one per arriving increment once a solution exists, each the anchor
// solution (as published) mechanized through the increments after it, so that a subscriber can
// reproduce every output bit for bit from the bus; and it stays close to the deterministic
// solution of the same time (it lacks only the fixes after its anchor).
TEST(LowLatencyOutput, ReproducibleFromItsAnchorSolutionAndCloseToTheFilter) {
  auto cfg = nav_filter::parseFilterConfig(
      YAML::Load("initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}\n"
                 "mode: loosely_coupled\n"
                 "inputs: {imu: {id: 1, period_s: 0.01}, gnss_fix: {id: 1, period_s: 1.0}}\n"
                 "sequencer_max_wait_s: 2.0\n"  // waits for the first fix (1 s into the data)
                 "low_latency_output: {enabled: true}\n"));
  bus::HealthCounters health("test");
  std::vector<NavigationSolution> solutions, fast;
  std::vector<std::int64_t> ahead_ns;
  const nav_filter::FilterPipeline* pipeline_ptr = nullptr;
  nav_filter::FilterPipeline pipeline(
      cfg, health,
      {[&](const NavigationSolution& s) { solutions.push_back(s); }, nullptr,
       [&](const NavigationSolution& s) {
         fast.push_back(s);
         // How far this output is ahead of what the ordered filter has integrated.
         ahead_ns.push_back(static_cast<std::int64_t>(s.time_gps_ns()) -
                            pipeline_ptr->engine().state().time_ns);
       }});
  pipeline_ptr = &pipeline;
  sim::ScenarioConfig src_cfg = sourceConfig();
  src_cfg.gnss_every_n_increments = 100;
  src_cfg.segments.resize(1);
  src_cfg.segments[0].duration_s = 100.0;
  src_cfg.segments[0].accel_mps2 = 0.5;
  sim::ScenarioSource src(src_cfg);
  std::vector<core::ImuIncrement> increments;
  std::uint64_t seq = 0, fix_seq = 0;
  std::int64_t now = 0;
  // The fixes come 35 ms late (as on a bus), so the filter holds the increments after them.
  std::vector<std::pair<std::int64_t, GnssFix>> late_fixes;
  for (int k = 0; k < 3000; ++k) {
    const sim::SensorFrame f = src.next();
    increments.push_back(f.increment);
    pipeline.onImu(bus::toIdl(f.increment, 1, ++seq));
    if (f.has_gnss)
      late_fixes.emplace_back(f.time_ns + 35'000'000, sensor_sim::toIdl(f.fix, 1, ++fix_seq));
    while (!late_fixes.empty() && late_fixes.front().first <= f.time_ns) {
      pipeline.onGnssFix(late_fixes.front().second);
      late_fixes.erase(late_fixes.begin());
    }
    pipeline.pump(now += 10'000'000);
  }
  ASSERT_GT(solutions.size(), 100u);
  ASSERT_GT(fast.size(), 2500u);
  // Every output is its anchor, as published, mechanized by an independent strapdown.
  std::map<std::uint64_t, const NavigationSolution*> by_time;
  for (const auto& s : solutions) by_time[s.time_gps_ns()] = &s;
  std::size_t compared = 0;
  double max_diff_m = 0.0;
  std::uint64_t max_lead_ns = 0;  // how far an output runs ahead of its anchor
  for (const auto& out : fast) {
    EXPECT_EQ(out.output(), OUTPUT_LOW_LATENCY);
    max_lead_ns = std::max(max_lead_ns, out.time_gps_ns() - out.propagated_from_gps_ns());
    const auto anchor = by_time.find(out.propagated_from_gps_ns());
    ASSERT_NE(anchor, by_time.end()) << "output at " << out.time_gps_ns();
    const NavigationSolution& a = *anchor->second;
    EXPECT_LT(a.time_gps_ns(), out.time_gps_ns());
    core::NavState s;
    s.time_ns = static_cast<std::int64_t>(a.time_gps_ns());
    s.position = {a.latitude_rad(), a.longitude_rad(), a.height_m()};
    s.vel_ned_mps = Eigen::Vector3d(a.vel_ned_mps().data());
    s.q_b_to_n =
        Eigen::Quaterniond(a.q_b_to_n()[0], a.q_b_to_n()[1], a.q_b_to_n()[2], a.q_b_to_n()[3]);
    core::StrapdownNed ins(core::earth::GravityModel::kWgs84Normal);
    ins.initialize(s);
    const Eigen::Vector3d ba(a.accel_bias_b_mps2().data()), bg(a.gyro_bias_b_radps().data());
    for (core::ImuIncrement inc : increments) {
      if (inc.time_ns <= s.time_ns || inc.time_ns > static_cast<std::int64_t>(out.time_gps_ns()))
        continue;
      inc.delta_vel_b_mps -= ba * inc.interval_s;
      inc.delta_angle_b_rad -= bg * inc.interval_s;
      ins.propagate(inc);
    }
    EXPECT_EQ(ins.state().position.latitude_rad, out.latitude_rad());
    EXPECT_EQ(ins.state().vel_ned_mps.z(), out.vel_ned_mps()[2]);
    EXPECT_EQ(ins.state().q_b_to_n.w(), out.q_b_to_n()[0]);
    // Close to the deterministic solution of the same time, where there is one.
    const auto same = by_time.find(out.time_gps_ns());
    if (same != by_time.end()) {
      ++compared;
      const double dn = (same->second->latitude_rad() - out.latitude_rad()) * 6.4e6;
      const double de = (same->second->longitude_rad() - out.longitude_rad()) * 5.1e6;
      max_diff_m = std::max(max_diff_m, std::hypot(dn, de));
    }
  }
  std::printf(
      "low-latency outputs %zu, deterministic solutions %zu, compared %zu, max horizontal "
      "difference %.4f m, max lead over the anchor %.3f s\n",
      fast.size(), solutions.size(), compared, max_diff_m, 1e-9 * static_cast<double>(max_lead_ns));
  EXPECT_GT(pipeline.engine().counters().fixes_fused, 25u);
  // The filter holds the increments after a fix's time until the fix arrives (35 ms): the
  // outputs of those increments run ahead of it.
  const auto held = std::count_if(ahead_ns.begin(), ahead_ns.end(),
                                  [](std::int64_t a) { return a >= 30'000'000; });
  std::printf("outputs ahead of the filter by >= 30 ms: %td\n", held);
  EXPECT_GE(held, 25);
  EXPECT_GT(compared, 100u);
  EXPECT_LT(max_diff_m, 5.0);
  EXPECT_NE(pipeline.summary().find("low-latency outputs"), std::string::npos);
}

// A stream whose first sample is more than the jump tolerance ahead of the data taken so far
// is a forward-jump candidate until the samples after it confirm it. Which data was taken
// first depends on the order in which the streams' samples arrive: on a loaded machine a
// replayed car drive (GNSS from 3.2 s before the IMU) delivered the first fix, then the IMU's
// first block, then the fixes between them. The candidates the confirmation proves real are
// used, so the filter's input, and its solutions, do not depend on that order.
TEST(FilterPipelineOrder, AStreamStartingAfterAnotherGivesTheSameSolutionsInAnyArrivalOrder) {
  const auto cfg = seed001Filter();
  const sensor_sim::SimConfig sim = seed001Sim();
  // Given 10 s of the scenario's fixes and, from 3.5 s on, its IMU increments (numbered from 1),
  using Sample = std::variant<ImuIncrement, GnssFix>;
  std::vector<Sample> in_time_order;
  sim::ScenarioSource src(sim.scenario);
  sensor_sim::FrameSequence seq;
  const std::uint64_t imu_from_ns = sim.scenario.start_time_ns + 3'500'000'000;
  std::uint64_t imu_seq = 0;
  for (int k = 0; k < 2000; ++k) {
    sensor_sim::emitFrame(src.next(), sim, seq, [&](const auto& sample) {
      using T = std::decay_t<decltype(sample)>;
      if constexpr (std::is_same_v<T, GnssFix>) in_time_order.emplace_back(sample);
      if constexpr (std::is_same_v<T, ImuIncrement>) {
        if (sample.time_gps_ns() < imu_from_ns) return true;
        ImuIncrement renumbered = sample;
        renumbered.seq(++imu_seq);
        in_time_order.emplace_back(renumbered);
      }
      return true;
    });
  }
  const auto is_imu = [](const Sample& s) { return std::holds_alternative<ImuIncrement>(s); };
  const auto first_imu = std::find_if(in_time_order.begin(), in_time_order.end(), is_imu);
  ASSERT_GT(first_imu - in_time_order.begin(), 30);
  // and the same samples with the first fix, then the IMU's first 50 increments, then the rest
  // (each stream still in its own order),
  std::vector<Sample> reordered{in_time_order.front()};
  std::vector<Sample> rest;
  for (auto it = in_time_order.begin() + 1; it != in_time_order.end(); ++it) {
    const bool early_imu = is_imu(*it) && std::get<ImuIncrement>(*it).seq() <= 50;
    (early_imu ? reordered : rest).push_back(*it);
  }
  reordered.insert(reordered.end(), rest.begin(), rest.end());
  ASSERT_EQ(reordered.size(), in_time_order.size());

  struct Run {
    std::vector<NavigationSolution> solutions;
    std::uint64_t imu_accepted, imu_gaps, imu_rejected;
  };
  auto run = [&](const std::vector<Sample>& samples) {
    bus::HealthCounters health("test");
    Run r;
    nav_filter::FilterPipeline pipeline(
        cfg, health, {[&](const NavigationSolution& s) { r.solutions.push_back(s); }, nullptr});
    for (const Sample& s : samples) {
      if (const auto* inc = std::get_if<ImuIncrement>(&s)) pipeline.onImu(*inc);
      if (const auto* fix = std::get_if<GnssFix>(&s)) pipeline.onGnssFix(*fix);
      pipeline.pump(0);  // no wall time passes: only the order differs
    }
    pipeline.flush(0);
    const bus::StreamCounters& imu = *health.find(bus::topic::kImuIncrement);
    r.imu_accepted = imu.accepted;
    r.imu_gaps = imu.sequence_gaps;
    r.imu_rejected = imu.rejectedTotal();
    return r;
  };
  // when a filter takes each order,
  const Run ordered = run(in_time_order);
  const Run arrived = run(reordered);
  // then every increment is accepted in both, none missing,
  EXPECT_EQ(ordered.imu_accepted, imu_seq);
  EXPECT_EQ(arrived.imu_accepted, imu_seq);
  EXPECT_EQ(arrived.imu_rejected, 0u);
  EXPECT_EQ(arrived.imu_gaps, 0u);
  // and the solutions are the same, bit for bit.
  ASSERT_GT(ordered.solutions.size(), 5u);
  ASSERT_EQ(arrived.solutions.size(), ordered.solutions.size());
  for (std::size_t i = 0; i < ordered.solutions.size(); ++i) {
    const auto& a = ordered.solutions[i];
    const auto& b = arrived.solutions[i];
    ASSERT_EQ(a.time_gps_ns(), b.time_gps_ns()) << i;
    EXPECT_EQ(a.latitude_rad(), b.latitude_rad()) << i;
    EXPECT_EQ(a.vel_ned_mps(), b.vel_ned_mps()) << i;
    EXPECT_EQ(a.q_b_to_n(), b.q_b_to_n()) << i;
  }
}

TEST(SolutionFlags, AStreamLostIsThisFiltersOnlyWhenItFusesThatStream) {
  // Given a filter fusing IMU 1 and receiver 1's epochs (a second receiver, 2, on the bus for
  // the fault manager's cross-receiver test), when the fault manager declares receiver 2's
  // epochs lost, then that is not this filter's loss (measured before: its solutions carried
  // FAULT_GNSS_STREAM_LOST and its health said DEGRADED for the 5 s receiver 2 was silent);
  // receiver 1's is, and a fix stream only where fixes are fused.
  using Ids = nav_filter::SolutionFlags::InputIds;
  const Ids ids{1, 1u, std::nullopt, std::nullopt, std::nullopt};
  FilterCommand c;
  c.kind(CMD_EXCLUDE_STREAM);
  c.sensor(SOURCE_GNSS_OBS_STREAM);
  c.sensor_id(2);
  EXPECT_FALSE(nav_filter::SolutionFlags::streamFlag(c, ids));
  c.sensor_id(1);
  EXPECT_EQ(nav_filter::SolutionFlags::streamFlag(c, ids), FAULT_GNSS_STREAM_LOST);
  c.sensor(SOURCE_GNSS_FIX_STREAM);
  EXPECT_FALSE(nav_filter::SolutionFlags::streamFlag(c, ids));
  EXPECT_EQ(nav_filter::SolutionFlags::streamFlag(
                c, Ids{1, std::nullopt, 1u, std::nullopt, std::nullopt}),
            FAULT_GNSS_STREAM_LOST);
  c.sensor(SOURCE_ST_STREAM);
  EXPECT_FALSE(nav_filter::SolutionFlags::streamFlag(c, ids));
  c.sensor(SOURCE_IMU_STREAM);
  c.sensor_id(2);
  EXPECT_FALSE(nav_filter::SolutionFlags::streamFlag(c, ids));
}

TEST(SolutionFlags, TwoFusedReceiversShareTheFlagWhileEitherIsLost) {
  // Given a filter fusing receivers 1 and 2, when both are declared lost and receiver 1 comes
  // back, then the flag stays until receiver 2 is back too.
  const nav_filter::SolutionFlags::InputIds ids{1, 1u, std::nullopt, std::nullopt, 2u};
  nav_filter::SolutionFlags flags;
  FilterCommand c;
  c.sensor(SOURCE_GNSS_OBS_STREAM);
  for (const std::uint32_t id : {1u, 2u}) {
    c.kind(CMD_EXCLUDE_STREAM);
    c.sensor_id(id);
    const auto flag = nav_filter::SolutionFlags::streamFlag(c, ids);
    ASSERT_EQ(flag, FAULT_GNSS_STREAM_LOST);
    flags.applyStreamCommand(c, *flag);
  }
  c.kind(CMD_READMIT_STREAM);
  c.sensor_id(1);
  flags.applyStreamCommand(c, FAULT_GNSS_STREAM_LOST);
  EXPECT_EQ(flags.flags() & FAULT_GNSS_STREAM_LOST, FAULT_GNSS_STREAM_LOST);
  EXPECT_TRUE(flags.degraded());
  c.sensor_id(2);
  flags.applyStreamCommand(c, FAULT_GNSS_STREAM_LOST);
  EXPECT_EQ(flags.flags() & FAULT_GNSS_STREAM_LOST, 0u);
}
