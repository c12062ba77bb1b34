// bus::KeyReader: a block's keys read over member defaults, converted once, range-checked, and
// any key nothing read refused; and the parsers built on it give the structs' own defaults for
// every key a file leaves out (one place per default).
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "navbus/bus/key_reader.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"

namespace navbus::bus {
namespace {

constexpr FileUnit kMilliG{[](double v) { return v * units::kMilliG; }};

/// Expects `fn` to throw a ConfigError whose message contains `part`.
void expectError(const std::function<void()>& fn, const std::string& part) {
  try {
    fn();
    ADD_FAILURE() << "no ConfigError; expected one saying '" << part << "'";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

struct Block {
  double accel_mps2{0.25};
  std::int64_t wait_ns{500'000'000};
  int window{50};
  bool enabled{false};
};

Block read(const std::string& yaml) {
  Block b;
  KeyReader r(YAML::Load(yaml), "block");
  r.number("accel_mg", b.accel_mps2, {0.0, 100.0}, kMilliG)
      .seconds("wait_s", b.wait_ns, {0.001, 60.0})
      .integer("window", b.window, {2.0, 500.0})
      .value("enabled", b.enabled)
      .nested({"child"})
      .finish();
  return b;
}

TEST(KeyReader, AbsentKeysKeepTheMembersDefaults) {
  const Block b = read("{}");
  EXPECT_EQ(b.accel_mps2, 0.25);
  EXPECT_EQ(b.wait_ns, 500'000'000);
  EXPECT_EQ(b.window, 50);
  EXPECT_FALSE(b.enabled);
}

TEST(KeyReader, PresentKeysAreConvertedOnce) {
  const Block b = read("{accel_mg: 2, wait_s: 1.5, window: 7, enabled: true, child: {x: 1}}");
  EXPECT_EQ(b.accel_mps2, 2.0 * units::kMilliG);
  EXPECT_EQ(b.wait_ns, 1'500'000'000);
  EXPECT_EQ(b.window, 7);
  EXPECT_TRUE(b.enabled);
}

TEST(KeyReader, ErrorsNameThePathAndTheValue) {
  expectError([] { read("{accel_mg: 200}"); }, "block.accel_mg = 200 is outside");
  expectError([] { read("{window: 2.5}"); }, "block.window = 2.5");
  expectError([] { read("{accel_mgg: 1}"); }, "block.accel_mgg: unknown key");
  expectError([] { read("{wait_s: soon}"); }, "block.wait_s");
}

TEST(KeyReader, ChoiceListsTheNames) {
  enum class Mode { kA, kB };
  Mode m = Mode::kA;
  expectError(
      [&m] {
        KeyReader(YAML::Load("{mode: c}"), "")
            .choice("mode", m, {{"a", Mode::kA}, {"b", Mode::kB}});
      },
      "mode = 'c' is not one of a | b");
}

TEST(OnePlacePerDefault, AFilterFileWithoutKeysGivesTheStructsDefaults) {
  const nav_filter::FilterConfig parsed = nav_filter::parseFilterConfig(
      YAML::Load("{inputs: {imu: {id: 1, period_s: 0.01}, gnss_fix: {id: 1, period_s: 1.0}}}"));
  const nav_filter::FilterConfig code;
  EXPECT_EQ(parsed.sequencer_max_wait_ns, code.sequencer_max_wait_ns);
  EXPECT_EQ(parsed.recovery_history_ns, code.recovery_history_ns);
  EXPECT_EQ(parsed.max_accel_compensation_mps2, code.max_accel_compensation_mps2);
  EXPECT_EQ(parsed.max_gyro_compensation_radps, code.max_gyro_compensation_radps);
  EXPECT_EQ(parsed.time_jump.tolerance_ns, code.time_jump.tolerance_ns);
  EXPECT_EQ(parsed.low_latency_max_buffered, code.low_latency_max_buffered);
  EXPECT_EQ(parsed.engine.solution_period_ns, code.engine.solution_period_ns);
  const core::FilterTuning& t = parsed.engine.tuning;
  const core::FilterTuning tc;
  EXPECT_EQ(t.accel_noise_mps2_per_sqrthz, tc.accel_noise_mps2_per_sqrthz);
  EXPECT_EQ(t.gyro_noise_radps_per_sqrthz, tc.gyro_noise_radps_per_sqrthz);
  EXPECT_EQ(t.accel_bias_sigma_mps2, tc.accel_bias_sigma_mps2);
  EXPECT_EQ(t.gyro_bias_sigma_radps, tc.gyro_bias_sigma_radps);
  EXPECT_EQ(t.heading_sigma_rad, tc.heading_sigma_rad);
  EXPECT_EQ(t.adaptive_floor_attitude_rad, tc.adaptive_floor_attitude_rad);
  EXPECT_EQ(t.failed_gyro_bias_sigma_radps, tc.failed_gyro_bias_sigma_radps);
  EXPECT_EQ(parsed.engine.mdf.stationarity.gyro_std_radps,
            core::StationarityConfig{}.gyro_std_radps);
  EXPECT_EQ(parsed.engine.mdf.constraint_period_s, core::MdfConfig{}.constraint_period_s);
  EXPECT_EQ(parsed.engine.alignment.max_heading_sigma_rad,
            core::InitialAlignmentConfig{}.max_heading_sigma_rad);
}

TEST(OnePlacePerDefault, AnEmptyScenarioGivesTheStructsDefaults) {
  const sensor_sim::SimConfig parsed = sensor_sim::parseSimConfig(YAML::Load("{}"));
  const sensor_sim::SimConfig code;
  const sim::ScenarioConfig& s = parsed.scenario;
  EXPECT_EQ(s.imu_period_ns, code.scenario.imu_period_ns);
  EXPECT_EQ(s.raw_samples_per_increment, code.scenario.raw_samples_per_increment);
  EXPECT_EQ(s.gnss_every_n_increments, code.scenario.gnss_every_n_increments);
  EXPECT_EQ(s.star_tracker_every_n_increments, code.scenario.star_tracker_every_n_increments);
  EXPECT_EQ(s.gnss.max_satellites, code.scenario.gnss.max_satellites);
  EXPECT_EQ(s.gnss.elevation_mask_rad, code.scenario.gnss.elevation_mask_rad);
  EXPECT_EQ(s.star_tracker.noise_rad, code.scenario.star_tracker.noise_rad);
  EXPECT_EQ(s.star_tracker.bias_rad, code.scenario.star_tracker.bias_rad);
  EXPECT_EQ(s.dither_spec.accel_cross_axis_mps2, code.scenario.dither_spec.accel_cross_axis_mps2);
  EXPECT_EQ(s.dither_spec.peak_rate_min_radps, code.scenario.dither_spec.peak_rate_min_radps);
  EXPECT_EQ(s.vibration.accel_rms_mps2, code.scenario.vibration.accel_rms_mps2);
  EXPECT_EQ(parsed.fast_pacing_block_s, code.fast_pacing_block_s);
  EXPECT_EQ(parsed.wait_for_readers_s, code.wait_for_readers_s);
  EXPECT_EQ(parsed.min_readers.raw_imu, code.min_readers.raw_imu);
}

}  // namespace
}  // namespace navbus::bus
