// The fault loop's hardest paths in one process, with the real GlrDetector and FaultPipeline
// answering the real FilterPipeline (the offline runner: each decision's commands reach the
// filter at once): an accelerometer step decided, compensated or re-learned and the filter
// restored to before the onset; the same with a history too short to reach the onset (counted,
// not silent); a satellite excluded for a ramp and readmitted once its residuals pass again.
#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/evaluation/evaluation.hpp"
#include "navbus/evaluation/offline_runner.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "test_paths.hpp"

namespace evaluation = navbus::evaluation;

namespace {

const std::string kScenarios = navbus::test_paths::scenarioDir();
const std::string kConfig = navbus::test_paths::configDir();
constexpr std::int64_t kStart = 1'400'000'000'000'000'000;  // the scenarios' start time

evaluation::OfflineResult runLoop(const std::string& scenario, double duration_s,
                                  double history_s = -1.0, const std::string& faults_yaml = "") {
  YAML::Node sy = YAML::Clone(navbus::bus::loadYamlFile(kScenarios + "/" + scenario));
  if (!faults_yaml.empty()) sy["faults"] = YAML::Load(faults_yaml);
  evaluation::OfflineSetup s;
  s.sim = navbus::sensor_sim::parseSimConfig(sy);
  s.sim.scenario.seed = 3;
  s.filter = navbus::nav_filter::parseFilterConfig(
      navbus::bus::loadYamlFile(kConfig + "/filter_seed000_tc.yaml"));
  if (history_s >= 0.0) s.filter.recovery_history_ns = static_cast<std::int64_t>(history_s * 1e9);
  s.filter.engine.initial_state = evaluation::initialTruth(s.sim.scenario);
  s.fault_manager = navbus::fault_manager::parseFaultManagerConfig(
      navbus::bus::loadYamlFile(kConfig + "/fault_manager.yaml"));
  s.duration_s = duration_s;
  return evaluation::runOffline(s);
}

double secondsOf(std::uint64_t time_gps_ns) {
  return 1e-9 * static_cast<double>(static_cast<std::int64_t>(time_gps_ns) - kStart);
}

bool namesAccelerometerX(const navbus::FaultDecision& d) {
  if (d.source() == navbus::SOURCE_ACCELEROMETER && d.axis() == 0) return true;
  return std::any_of(d.candidates().begin(), d.candidates().end(), [](const auto& c) {
    return c.source() == navbus::SOURCE_ACCELEROMETER && c.axis() == 0;
  });
}

/// The run's largest 3-D error / 3-D sigma over solutions that claim a valid covariance.
double worstUnflaggedRatio(const evaluation::OfflineResult& r) {
  double worst = 0.0;
  for (const evaluation::EpochError& e : r.errors) {
    if (e.covariance_valid && e.pos_sigma_ned_m.norm() > 0.0)
      worst = std::max(worst, e.pos_ned_m.norm() / e.pos_sigma_ned_m.norm());
  }
  return worst;
}

}  // namespace

TEST(FaultLoopPaths, AccelerometerStepIsDecidedCompensatedAndRolledBackToItsOnset) {
  const evaluation::OfflineResult r = runLoop("seed000_accel_step.yaml", 640.0);  // step at 502 s
  ASSERT_GE(r.decisions.size(), 1u) << r.fault_summary;
  EXPECT_LE(r.decisions.size(), 3u) << r.fault_summary;
  const navbus::FaultDecision& first = r.decisions.front();
  EXPECT_TRUE(namesAccelerometerX(first)) << "decided source " << first.source();
  EXPECT_GT(secondsOf(first.time_gps_ns()), 502.0);
  EXPECT_NEAR(secondsOf(first.onset_time_gps_ns()), 502.0, 5.0);
  const bool answered = std::any_of(r.commands.begin(), r.commands.end(), [](const auto& c) {
    return (c.kind() == navbus::CMD_COMPENSATE_BIAS || c.kind() == navbus::CMD_RELEARN_BIAS) &&
           c.onset_time_gps_ns() > 0;
  });
  EXPECT_TRUE(answered) << "no compensation or re-learn carrying the onset";
  EXPECT_NE(r.summary.find("(onset beyond history 0)"), std::string::npos) << r.summary;
  EXPECT_EQ(r.summary.find("recoveries from onset 0 "), std::string::npos)
      << "the filter was not restored to before the onset: " << r.summary;
  EXPECT_LT(worstUnflaggedRatio(r), 5.0);
  const evaluation::EpochError& last = r.errors.back();
  EXPECT_LT(last.pos_ned_m.norm(), 3.0 * last.pos_sigma_ned_m.norm())
      << "after the loop the error is back within the filter's own 3 sigma";
}

TEST(FaultLoopPaths, ARollbackTheHistoryCannotReachIsCountedNotSilent) {
  // 3 s of history: the decision comes more than 3 s after the onset.
  const evaluation::OfflineResult r = runLoop("seed000_accel_step.yaml", 560.0, 3.0);
  ASSERT_GE(r.decisions.size(), 1u) << r.fault_summary;
  EXPECT_EQ(r.summary.find("(onset beyond history 0)"), std::string::npos)
      << "a restore the history could not reach must be counted: " << r.summary;
}

TEST(FaultLoopPaths, AnExcludedSatelliteIsReadmittedOnceItsResidualsPassAgain) {
  const evaluation::OfflineResult r =
      runLoop("seed000_pseudorange_ramp.yaml", 800.0, -1.0,
              "[{type: pseudorange_ramp, sv_id: 13, start_s: 650, end_s: 700, slope_mps: 25, "
              "saturation_m: 250}]");
  auto command = [&r](navbus::CommandKind kind) {
    return std::find_if(r.commands.begin(), r.commands.end(),
                        [kind](const auto& c) { return c.kind() == kind && c.sv_id() == 13; });
  };
  const auto excluded = command(navbus::CMD_EXCLUDE_SATELLITE);
  ASSERT_NE(excluded, r.commands.end()) << r.fault_summary;
  const auto readmitted = command(navbus::CMD_READMIT_SATELLITE);
  ASSERT_NE(readmitted, r.commands.end()) << "sv 13 never readmitted: " << r.fault_summary;
  // The fault ends at 700 s; its residuals must pass for pass_time_s (30 s) first.
  EXPECT_GE(secondsOf(readmitted->time_gps_ns()), 730.0);
  EXPECT_NE(r.fault_summary.find("readmitted 1"), std::string::npos) << r.fault_summary;
  EXPECT_LT(worstUnflaggedRatio(r), 5.0);
}
