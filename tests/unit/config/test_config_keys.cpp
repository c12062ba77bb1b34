// Configuration files are strict: a key no parser reads (a typo) is an error naming the key and
// the file that spells it, for every parser and at every level; every shipped file passes.
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using navbus::bus::ConfigError;

namespace {

class ConfigKeys : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("navbus-config-keys-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }

  /// The message of the ConfigError parsing `path` throws ("" when it does not throw).
  template <class Parse>
  static std::string errorOf(const std::string& path, Parse parse) {
    try {
      navbus::bus::parseFile(path, parse);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

const std::string kSrc = navbus::test_paths::configDir();
const std::string kScenarios = navbus::test_paths::scenarioDir();

auto filter = [](const YAML::Node& n) { return navbus::nav_filter::parseFilterConfig(n); };
auto faults = [](const YAML::Node& n) { return navbus::fault_manager::parseFaultManagerConfig(n); };
auto scenario = [](const YAML::Node& n) { return navbus::sensor_sim::parseSimConfig(n); };

::testing::AssertionResult names(const std::string& message, const std::string& key,
                                 const std::string& file) {
  if (message.find(key + ": unknown key") == std::string::npos)
    return ::testing::AssertionFailure() << "'" << message << "' does not name key " << key;
  if (message.find("'" + file + "'") == std::string::npos)
    return ::testing::AssertionFailure() << "'" << message << "' does not name file " << file;
  return ::testing::AssertionSuccess();
}

}  // namespace

TEST_F(ConfigKeys, FilterTypoAtEveryLevelNamesKeyAndFile) {
  for (const auto& [text, key] : std::vector<std::pair<std::string, std::string>>{
           {"mdoe: tightly_coupled\n", "mdoe"},
           {"ekf: {gate_sigmaa: 3}\n", "ekf.gate_sigmaa"},
           {"inputs: {imu: {id: 1, period_s: 0.01, rate_hz: 100}}\n", "inputs.imu.rate_hz"},
           {"initial_state: {latitude_deg: 1, longitude_deg: 2, height_m: 3, heading_deg: 4}\n",
            "initial_state.heading_deg"},
           {"multi_dimensional: {stationary: {speed: 1}}\n", "multi_dimensional.stationary.speed"},
           {"recovery: {history: 10}\n", "recovery.history"},
           {"alignment: {static_window: 30}\n", "alignment.static_window"}}) {
    const std::string path = write("filter.yaml", "extends: " + kSrc + "/filter.yaml\n" + text);
    EXPECT_TRUE(names(errorOf(path, filter), key, path)) << text;
  }
}

TEST_F(ConfigKeys, WithoutAnInitialStateTheFilterAlignsAndNeedsAGnssPosition) {
  // No initial_state: the filter aligns from its inputs ...
  const std::string ok =
      write("ok.yaml",
            "mode: inertial_only\ninputs: {imu: {id: 1, period_s: 0.01}, "
            "gnss_fix: {id: 1, period_s: 1}}\nalignment: {static_window_s: 30}\n");
  const auto c = navbus::bus::parseFile(ok, filter);
  EXPECT_EQ(c.engine.start, navbus::core::StartSource::kAligned);
  EXPECT_DOUBLE_EQ(c.engine.alignment.static_window_s, 30.0);
  EXPECT_DOUBLE_EQ(c.engine.alignment.budget.accel_bias_sigma_mps2,
                   c.engine.tuning.accel_bias_sigma_mps2);
  // ... which needs a GNSS position: refused, naming the file, without one.
  const std::string bad =
      write("bad.yaml", "mode: inertial_only\ninputs: {imu: {id: 1, period_s: 0.01}}\n");
  const std::string message = errorOf(bad, filter);
  EXPECT_NE(message.find("inputs.gnss_fix or inputs.gnss_observations"), std::string::npos)
      << message;
  EXPECT_NE(message.find(bad), std::string::npos) << message;
  // `initial_state: align` overrides an extended file's state; another word is an error.
  const std::string over =
      write("over.yaml", "extends: " + kSrc + "/filter_seed000_tc.yaml\ninitial_state: align\n");
  EXPECT_EQ(navbus::bus::parseFile(over, filter).engine.start, navbus::core::StartSource::kAligned);
  const std::string word =
      write("word.yaml", "extends: " + kSrc + "/filter_seed000_tc.yaml\ninitial_state: alig\n");
  EXPECT_NE(errorOf(word, filter).find("initial_state = 'alig'"), std::string::npos)
      << errorOf(word, filter);
  // A value out of range names the key.
  const std::string range = write(
      "range.yaml", "extends: " + kSrc + "/filter.yaml\nalignment: {course_sigma_deg: 200}\n");
  EXPECT_NE(errorOf(range, filter).find("alignment.course_sigma_deg"), std::string::npos);
}

TEST_F(ConfigKeys, WaitingForTheReceiversJudgementNeedsTheirEpochs) {
  // fault_monitor.receivers_judged holds the epoch after one for the fault manager's judgement
  // (its period is required of every input): a filter without pseudorange epochs is refused
  // naming the key; config/filter_dual_receivers.yaml passes.
  const std::string loose = write("loose.yaml", "extends: " + kSrc +
                                                    "/filter_seed001_lc.yaml\n"
                                                    "fault_monitor: {receivers_judged: true}\n");
  EXPECT_NE(errorOf(loose, filter)
                .find("fault_monitor.receivers_judged = true needs inputs.gnss_observations"),
            std::string::npos)
      << errorOf(loose, filter);
  EXPECT_TRUE(navbus::bus::parseFile(kSrc + "/filter_dual_receivers.yaml", filter)
                  .fault_monitor->receivers_judged);
}

TEST_F(ConfigKeys, TypoInAnExtendedFileNamesThatFile) {
  const std::string base =
      write("base.yaml", "extends: " + kSrc + "/fault_manager.yaml\nglr: {thresold: 40}\n");
  const std::string top = write("top.yaml", "extends: base.yaml\nvehicle_id: 2\n");
  EXPECT_TRUE(names(errorOf(top, faults), "glr.thresold", base));
  // The same typo in the derived file: that file is named.
  const std::string top2 = write(
      "top2.yaml", "extends: " + kSrc + "/fault_manager.yaml\ndither: {windw_samples: 256}\n");
  EXPECT_TRUE(names(errorOf(top2, faults), "dither.windw_samples", top2));
}

TEST_F(ConfigKeys, ScenarioTypoInListsAndSections) {
  const std::string base = kScenarios + "/seed000_aircraft.yaml";
  for (const auto& [text, key] : std::vector<std::pair<std::string, std::string>>{
           {"faults:\n  - {type: pseudorange_ramp, start_s: 10, sv_id: 3, slope: 2}\n",
            "faults[0].slope"},
           {"faults:\n  - {type: sensor_stuck, start_s: 10, axis: x, magnitude_mg: 2}\n",
            "faults[0].magnitude_mg"},
           {"timing: {imu_rate: 100}\n", "timing.imu_rate"},
           {"gnss: {pseudorange_sigma: 3}\n", "gnss.pseudorange_sigma"},
           {"vehicle: {segments: [{type: turn, duration_s: 5, turn_rate_dps: 1, accel_mps2: 1}]}\n",
            "vehicle.segments[0].accel_mps2"},
           {"imu: {accel_bias_sigma_mg: 1}\n", "imu.accel_bias_sigma_mg"},
           {"seeed: 3\n", "seeed"}}) {
    const std::string path = write("scenario.yaml", "extends: " + base + "\n" + text);
    EXPECT_TRUE(names(errorOf(path, scenario), key, path)) << text;
  }
}

TEST_F(ConfigKeys, EveryShippedConfigurationPasses) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(kSrc)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() != ".yaml") continue;
    const std::string path = e.path().string();
    if (name.rfind("filter", 0) == 0) {
      EXPECT_EQ(errorOf(path, filter), "") << path;
    } else if (name.rfind("fault_manager", 0) == 0) {
      EXPECT_EQ(errorOf(path, faults), "") << path;
    } else {
      ADD_FAILURE() << path << ": no parser known for this file in the test";
    }
    ++n;
  }
  for (const auto& e : fs::directory_iterator(kScenarios)) {
    if (e.path().extension() != ".yaml") continue;
    EXPECT_EQ(errorOf(e.path().string(), scenario), "") << e.path();
    ++n;
  }
  EXPECT_GE(n, 30);
}

TEST_F(ConfigKeys, AFixVelocityOffsetIsALagTheVelocityHistoryReaches) {
  const auto with = [&](const std::string& name, const std::string& value) {
    return write(name,
                 "mode: loosely_coupled\ninputs: {imu: {id: 1, period_s: 0.01}, gnss_fix: "
                 "{id: 1, period_s: 0.25, velocity_time_offset_s: " +
                     value + "}}\n");
  };
  const auto c = navbus::bus::parseFile(with("ok.yaml", "-0.132"), filter);
  EXPECT_EQ(c.gnss_fix->velocity_time_offset_ns, -132'000'000);
  // A velocity valid after its stamp is not a lag: refused, naming the key and the value.
  const std::string ahead = errorOf(with("ahead.yaml", "0.1"), filter);
  EXPECT_NE(ahead.find("inputs.gnss_fix.velocity_time_offset_s"), std::string::npos) << ahead;
  // Further back than 62 IMU periods (0.62 s at 100 Hz): refused with the history's reach.
  const std::string far = errorOf(with("far.yaml", "-0.7"), filter);
  EXPECT_NE(far.find("reaches further back than the velocity history"), std::string::npos) << far;
  // The key belongs to the fix only.
  const std::string imu = write("imu.yaml",
                                "inputs: {imu: {id: 1, period_s: 0.01, "
                                "velocity_time_offset_s: -0.1}}\n");
  EXPECT_TRUE(names(errorOf(imu, filter), "inputs.imu.velocity_time_offset_s", imu));
}

TEST_F(ConfigKeys, TheMultiDimensionalFilterNamesTheStatesItsResetsTouch) {
  const auto with = [&](const std::string& name, const std::string& block) {
    return write(name,
                 "mode: multi_dimensional\ninputs: {imu: {id: 1, period_s: 0.01}, gnss_fix: "
                 "{id: 1, period_s: 0.25}}\nmulti_dimensional: " +
                     block + "\n");
  };
  const auto c =
      navbus::bus::parseFile(with("ok.yaml",
                                  "{unestimated_states: none, reset_states: [velocity, heading], "
                                  "nhc_velocity_pitch_per_accel_deg_per_mps2: -0.34}"),
                             filter);
  EXPECT_EQ(c.engine.mdf.unestimated, navbus::core::ReducedStates::kNone);
  EXPECT_DOUBLE_EQ(c.engine.mdf.nhc_velocity_pitch_per_accel_rad_per_mps2, -0.34 * M_PI / 180);
  EXPECT_EQ(c.engine.mdf.reset_blocks.count(), 2u);
  EXPECT_TRUE(
      c.engine.mdf.reset_blocks[static_cast<std::size_t>(navbus::core::ResetBlock::kHeading)]);
  EXPECT_FALSE(
      c.engine.mdf.reset_blocks[static_cast<std::size_t>(navbus::core::ResetBlock::kPosition)]);
  const auto defaults = navbus::bus::parseFile(with("defaults.yaml", "{}"), filter);
  EXPECT_EQ(defaults.engine.mdf.reset_blocks.count(), 4u);
  EXPECT_EQ(defaults.engine.mdf.unestimated, navbus::core::ReducedStates::kConsidered);
  const std::string unknown =
      errorOf(with("unknown.yaml", "{reset_states: [position, attitude]}"), filter);
  EXPECT_NE(unknown.find("multi_dimensional.reset_states: 'attitude' is not one of position | "
                         "velocity | level | heading"),
            std::string::npos)
      << unknown;
  const std::string scalar = errorOf(with("scalar.yaml", "{reset_states: position}"), filter);
  EXPECT_NE(scalar.find("multi_dimensional.reset_states must be a list of names"),
            std::string::npos)
      << scalar;
}

TEST_F(ConfigKeys, ScaleFactorSigmasAreInPartsPerMillionAndBounded) {
  const auto with = [&](const std::string& name, const std::string& block) {
    return write(name,
                 "mode: loosely_coupled\ninputs: {imu: {id: 1, period_s: 0.01}, gnss_fix: "
                 "{id: 1, period_s: 0.25}}\nekf: " +
                     block + "\n");
  };
  const auto c = navbus::bus::parseFile(
      with("ok.yaml", "{accel_scale_factor_sigma_ppm: 1000, gyro_scale_factor_sigma_ppm: 250}"),
      filter);
  EXPECT_DOUBLE_EQ(c.engine.tuning.accel_scale_sigma, 1e-3);
  EXPECT_DOUBLE_EQ(c.engine.tuning.gyro_scale_sigma, 2.5e-4);
  const auto off = navbus::bus::parseFile(with("off.yaml", "{}"), filter);
  EXPECT_EQ(off.engine.tuning.accel_scale_sigma, 0.0);
  const std::string negative =
      errorOf(with("negative.yaml", "{gyro_scale_factor_sigma_ppm: -5}"), filter);
  EXPECT_NE(negative.find("ekf.gyro_scale_factor_sigma_ppm"), std::string::npos) << negative;
  EXPECT_NE(negative.find("-5"), std::string::npos) << negative;
}

TEST_F(ConfigKeys, TheCovariancePeriodIsInSecondsAndBounded) {
  const auto with = [&](const std::string& name, const std::string& block) {
    return write(name,
                 "mode: loosely_coupled\ninputs: {imu: {id: 1, period_s: 0.005}, gnss_fix: "
                 "{id: 1, period_s: 0.1}}\nekf: " +
                     block + "\n");
  };
  const auto c = navbus::bus::parseFile(with("ok.yaml", "{covariance_period_s: 0.1}"), filter);
  EXPECT_DOUBLE_EQ(c.engine.tuning.covariance_period_s, 0.1);
  const auto off = navbus::bus::parseFile(with("off.yaml", "{}"), filter);
  EXPECT_EQ(off.engine.tuning.covariance_period_s, 0.0);  // every increment, as before
  const std::string long_period = errorOf(with("long.yaml", "{covariance_period_s: 2.5}"), filter);
  EXPECT_NE(long_period.find("ekf.covariance_period_s"), std::string::npos) << long_period;
  EXPECT_NE(long_period.find("2.5"), std::string::npos) << long_period;
}

TEST_F(ConfigKeys, ProtectionLevelsOnFixesNeedTheCentralizedFilter) {
  const auto with = [&](const std::string& name, const std::string& mode,
                        const std::string& fusion) {
    return write(name, "mode: " + mode + "\nfusion: " + fusion +
                           "\ninputs: {imu: {id: 1, period_s: 0.01}, gnss_fix: {id: 1, "
                           "period_s: 0.25}}\nintegrity: {detector: {window_epochs: 20}}\n"
                           "consistency: {inflate_imu_biases_on_alarm: true}\n");
  };
  const auto loose =
      navbus::bus::parseFile(with("lc.yaml", "loosely_coupled", "centralized"), filter);
  EXPECT_TRUE(loose.engine.integrity.enabled);
  EXPECT_TRUE(loose.engine.consistency.inflate_imu_biases_on_alarm);
  const auto mdf =
      navbus::bus::parseFile(with("mdf.yaml", "multi_dimensional", "centralized"), filter);
  EXPECT_TRUE(mdf.engine.integrity.enabled);
  const std::string adaptive =
      errorOf(with("adaptive.yaml", "loosely_coupled", "adaptive"), filter);
  EXPECT_NE(adaptive.find("integrity.enabled: true on GNSS fixes needs fusion: centralized"),
            std::string::npos)
      << adaptive;
}

TEST_F(ConfigKeys, AdaptiveNoiseNamesItsStreamsAndKeepsItsBoundsInOrder) {
  const auto with = [&](const std::string& name, const std::string& block,
                        const std::string& fusion = "centralized") {
    return write(name, "mode: loosely_coupled\nfusion: " + fusion +
                           "\ninputs: {imu: {id: 1, period_s: 0.01}, gnss_fix: {id: 1, "
                           "period_s: 0.25}}\nadaptive_noise: " +
                           block + "\n");
  };
  const auto c = navbus::bus::parseFile(
      with("ok.yaml",
           "{enabled: true, window_epochs: 4, floor: 1, ceiling: 16, streams: "
           "[fix_position, non_holonomic]}"),
      filter);
  EXPECT_TRUE(c.engine.adaptive_noise.enabled);
  EXPECT_EQ(c.engine.adaptive_noise.window_epochs, 4);
  EXPECT_DOUBLE_EQ(c.engine.adaptive_noise.ceiling, 16.0);
  EXPECT_EQ(c.engine.adaptive_noise_streams.count(), 2u);
  EXPECT_TRUE(c.engine.adaptive_noise_streams[static_cast<std::size_t>(
      navbus::core::NoiseStream::kNonHolonomic)]);
  const std::string unknown =
      errorOf(with("unknown.yaml", "{enabled: true, streams: [fix_heading]}"), filter);
  EXPECT_NE(unknown.find("adaptive_noise.streams: 'fix_heading' is not one of"), std::string::npos)
      << unknown;
  const std::string order =
      errorOf(with("order.yaml", "{enabled: true, floor: 4, ceiling: 2}"), filter);
  EXPECT_NE(order.find("adaptive_noise.ceiling: 2 is below adaptive_noise.floor: 4"),
            std::string::npos)
      << order;
  // The adaptive structure estimates R itself: not both.
  const std::string both = errorOf(with("both.yaml", "{enabled: true}", "adaptive"), filter);
  EXPECT_NE(both.find("adaptive_noise.enabled: true with fusion: adaptive"), std::string::npos)
      << both;
}

TEST_F(ConfigKeys, AdaptiveProcessNoiseKeepsItsBoundsInOrderInTheCentralizedFilter) {
  const auto with = [&](const std::string& name, const std::string& block,
                        const std::string& fusion = "centralized") {
    return write(name, "mode: loosely_coupled\nfusion: " + fusion +
                           "\ninputs: {imu: {id: 1, period_s: 0.01}, gnss_fix: {id: 1, "
                           "period_s: 0.25}}\nadaptive_process_noise: " +
                           block + "\n");
  };
  const auto c = navbus::bus::parseFile(
      with("ok.yaml", "{enabled: true, memory_s: 300, prior_rows: 2, floor: 0.5, ceiling: 16}"),
      filter);
  const navbus::core::ProcessNoiseScaleConfig& n = c.engine.adaptive_process_noise;
  EXPECT_TRUE(n.enabled);
  EXPECT_DOUBLE_EQ(n.memory_s, 300.0);
  EXPECT_DOUBLE_EQ(n.prior_rows, 2.0);
  EXPECT_DOUBLE_EQ(n.floor, 0.5);
  EXPECT_DOUBLE_EQ(n.ceiling, 16.0);
  const std::string order =
      errorOf(with("order.yaml", "{enabled: true, floor: 4, ceiling: 2}"), filter);
  EXPECT_NE(
      order.find("adaptive_process_noise.ceiling: 2 is below adaptive_process_noise.floor: 4"),
      std::string::npos)
      << order;
  const std::string memory = errorOf(with("memory.yaml", "{enabled: true, memory_s: 0}"), filter);
  EXPECT_NE(memory.find("memory_s"), std::string::npos) << memory;
  // The adaptive structure (seed 001) adapts R its own way, in a filter this one does not track.
  const std::string adaptive =
      errorOf(with("adaptive.yaml", "{enabled: true}", "adaptive"), filter);
  EXPECT_NE(adaptive.find("adaptive_process_noise.enabled: true with fusion: adaptive"),
            std::string::npos)
      << adaptive;
}

TEST_F(ConfigKeys, MountingMisalignmentStatesBelongToTheMultiDimensionalFilter) {
  const auto with = [&](const std::string& name, const std::string& mode, const std::string& rest) {
    return write(name, "mode: " + mode +
                           "\ninputs: {imu: {id: 1, period_s: 0.01}, gnss_fix: {id: 1, "
                           "period_s: 0.25}}\nekf: {mounting_misalignment_sigma_deg: 1.5, "
                           "mounting_misalignment_rw_deg_per_sqrts: 0.001}\n" +
                           rest);
  };
  const auto c = navbus::bus::parseFile(
      with("ok.yaml", "multi_dimensional", "multi_dimensional: {nhc_with_gnss: true}\n"), filter);
  EXPECT_NEAR(c.engine.tuning.mounting_misalignment_sigma_rad, 1.5 * M_PI / 180.0, 1e-15);
  EXPECT_NEAR(c.engine.tuning.mounting_misalignment_rw_rad_per_sqrts, 0.001 * M_PI / 180.0, 1e-18);
  EXPECT_TRUE(c.engine.mdf.nhc_with_gnss);
  const std::string loose = errorOf(with("loose.yaml", "loosely_coupled", ""), filter);
  EXPECT_NE(loose.find("ekf.mounting_misalignment_sigma_deg (1.5 deg) needs mode: "
                       "multi_dimensional"),
            std::string::npos)
      << loose;
}

TEST_F(ConfigKeys, TheFixPositionErrorBelongsToLooseCouplingWithBothSigmas) {
  const auto with = [&](const std::string& name, const std::string& mode, const std::string& ekf) {
    return write(name, "mode: " + mode + "\ninputs: {imu: {id: 1, period_s: 0.01}, " +
                           (mode == "tightly_coupled" ? "gnss_observations" : "gnss_fix") +
                           ": {id: 1, period_s: 0.25}}\nekf: " + ekf + "\n");
  };
  const auto c = navbus::bus::parseFile(
      with("ok.yaml", "loosely_coupled",
           "{fix_position_error_sigma_h_m: 0.03, fix_position_error_sigma_v_m: 0.05}"),
      filter);
  EXPECT_DOUBLE_EQ(c.engine.tuning.fix_position_error_sigma_h_m, 0.03);
  EXPECT_DOUBLE_EQ(c.engine.tuning.fix_position_error_correlation_time_s, 30.0);
  const std::string tc =
      errorOf(with("tc.yaml", "tightly_coupled",
                   "{fix_position_error_sigma_h_m: 0.03, fix_position_error_sigma_v_m: 0.05}"),
              filter);
  EXPECT_NE(tc.find("ekf.fix_position_error_sigma_h_m (0.03 m) needs mode: loosely_coupled"),
            std::string::npos)
      << tc;
  const std::string no_v =
      errorOf(with("no_v.yaml", "loosely_coupled", "{fix_position_error_sigma_h_m: 0.03}"), filter);
  EXPECT_NE(no_v.find("ekf.fix_position_error_sigma_v_m (0 m) must be positive"), std::string::npos)
      << no_v;
}

TEST_F(ConfigKeys, TheLeastSquaresLaneNeedsAnIdOfItsOwn) {
  const auto with = [&](const std::string& name, const std::string& block) {
    return write(name, "extends: " + kSrc +
                           "/filter_triplex.yaml\nlanes:\n  least_squares: " + block + "\n");
  };
  const auto c = navbus::bus::parseFile(with("ok.yaml", "{lane_id: 9, preferred: true}"), filter);
  ASSERT_TRUE(c.lanes.least_squares_lane_id.has_value());
  EXPECT_EQ(*c.lanes.least_squares_lane_id, 9u);
  EXPECT_TRUE(c.lanes.least_squares_preferred);
  EXPECT_EQ(c.lanes.units.size(), 3u) << "the units stay as the file it extends gives them";
  const std::string unit = errorOf(with("unit.yaml", "{lane_id: 2}"), filter);
  EXPECT_NE(unit.find("lanes.least_squares.lane_id 2 is a unit's sensor_id"), std::string::npos)
      << unit;
  const std::string missing = errorOf(with("missing.yaml", "{preferred: true}"), filter);
  EXPECT_NE(missing.find("lanes.least_squares.lane_id is missing"), std::string::npos) << missing;
  const std::string zero = errorOf(with("zero.yaml", "{lane_id: 0}"), filter);
  EXPECT_NE(zero.find("lanes.least_squares.lane_id 0"), std::string::npos) << zero;
  const std::string typo = with("typo.yaml", "{lane_id: 9, prefered: true}");
  EXPECT_TRUE(names(errorOf(typo, filter), "lanes.least_squares.prefered", typo));
}
