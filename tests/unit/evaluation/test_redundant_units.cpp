// Further IMU units on the bus (imu_units): their increments go out under their own sensor ids
// in the same frames; a filter configured for one IMU refuses each as an unexpected source and
// counts it, and its solutions are bit for bit those of the same scenario without the units.
#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/evaluation/offline_runner.hpp"
#include "test_paths.hpp"

namespace evaluation = navbus::evaluation;

namespace {

evaluation::OfflineResult run(const YAML::Node& scenario, double duration_s) {
  evaluation::OfflineSetup s;
  s.sim = navbus::sensor_sim::parseSimConfig(scenario);
  s.filter = navbus::nav_filter::parseFilterConfig(navbus::bus::loadYamlFile(
      std::string(navbus::test_paths::configDir()) + "/filter_seed000_tc.yaml"));
  s.filter.engine.initial_state = evaluation::initialTruth(s.sim.scenario);
  s.duration_s = duration_s;
  return evaluation::runOffline(s);
}

}  // namespace

TEST(RedundantUnits, AOneImuFilterRefusesTheFurtherUnitsCountedAndUnchanged) {
  // Given the triplex scenario (sensor 1 and units 2 and 3, a gyro step on unit 2 at 502 s) and
  // the same scenario without the units, when each runs 600 s through the seed-000 filter (one
  // IMU, sensor 1), then the triplex run refuses 2 increments per frame as unexpected sources,
  // and both runs publish the same solutions bit for bit (the units' data never reach the
  // engine; unit 2's fault with them).
  const YAML::Node triplex = navbus::bus::loadYamlFile(
      std::string(navbus::test_paths::scenarioDir()) + "/seed000_triplex_gyro_step.yaml");
  ASSERT_EQ(navbus::sensor_sim::parseSimConfig(triplex).extra_imu_sensor_ids,
            (std::vector<std::uint32_t>{2, 3}));
  YAML::Node single = YAML::Clone(triplex);
  single.remove("imu_units");
  single.remove("faults");
  const evaluation::OfflineResult a = run(triplex, 600.0), b = run(single, 600.0);
  const auto refused = a.imu_rejected.find(navbus::REJECT_UNEXPECTED_SOURCE);
  ASSERT_NE(refused, a.imu_rejected.end()) << a.summary;
  EXPECT_EQ(refused->second, 2u * 60000u);
  EXPECT_TRUE(b.imu_rejected.empty());
  ASSERT_EQ(a.errors.size(), b.errors.size());
  ASSERT_GT(a.errors.size(), 500u);
  for (std::size_t i = 0; i < a.errors.size(); ++i) {
    ASSERT_EQ(a.errors[i].pos_ned_m, b.errors[i].pos_ned_m) << "solution " << i;
    ASSERT_EQ(a.errors[i].pos_sigma_ned_m, b.errors[i].pos_sigma_ned_m) << "solution " << i;
  }
}
