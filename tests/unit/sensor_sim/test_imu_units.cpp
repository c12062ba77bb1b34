// Redundant IMU units in a scenario (imu_units): each senses the body's motion in its own axes
// at its own place, faults addressed by sensor id reach that unit only, and the configuration
// refuses ids it cannot place, naming them.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/records/csv_table.hpp"
#include "navbus/sensor_sim/file_writer.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "test_paths.hpp"

using navbus::sim::ScenarioConfig;
using navbus::sim::ScenarioSource;
using navbus::sim::SensorFrame;

namespace {

YAML::Node scenarioYaml() {
  return navbus::bus::loadYamlFile(std::string(navbus::test_paths::scenarioDir()) +
                                   "/seed004_land_vehicle.yaml");
}

/// seed 004's drive with a perfect IMU (no error of any kind) and no vibration, so that what the
/// units output is the motion alone.
YAML::Node perfectDrive() {
  YAML::Node root = scenarioYaml();
  root["imu"] = YAML::Node(YAML::NodeType::Map);
  root["vibration"] = YAML::Node(YAML::NodeType::Map);
  root["vibration"]["enabled"] = false;
  root["dither"] = YAML::Node(YAML::NodeType::Map);
  root["dither"]["enabled"] = false;
  root["faults"] = YAML::Node(YAML::NodeType::Sequence);
  return root;
}

YAML::Node unit(int sensor_id, const std::vector<double>& rpy_deg,
                const std::vector<double>& lever_arm_m) {
  YAML::Node u;
  u["sensor_id"] = sensor_id;
  u["mounting_rpy_deg"] = rpy_deg;
  u["lever_arm_b_m"] = lever_arm_m;
  return u;
}

/// An IMU fault of `type` on one axis of the unit `sensor_id`, from `start_s`.
YAML::Node imuFault(const std::string& type, double start_s, const std::string& sensor,
                    const std::string& axis, int sensor_id) {
  YAML::Node f;
  f["type"] = type;
  f["start_s"] = start_s;
  f["sensor"] = sensor;
  f["axis"] = axis;
  f["sensor_id"] = sensor_id;
  return f;
}

navbus::sensor_sim::SimConfig parse(const YAML::Node& root) {
  return navbus::sensor_sim::parseSimConfig(root);
}

}  // namespace

TEST(ImuUnits, SenseTheBodyMotionInTheirOwnAxesAtTheirOwnPlace) {
  // Given the drive with a perfect primary IMU (sensor 1) and two perfect units, sensor 2 mounted
  // like the primary at its place and sensor 3 turned by (10, -20, 35) deg without a lever arm,
  // and sensor 4 at a lever arm of (0.5, -0.3, 0.2) m, when the scenario runs, then sensor 2 reads
  // what the primary reads, sensor 3 reads the primary's increments turned into its axes, and
  // sensor 4's extra specific force is the rigid body's w x (w x r) in steady turns (where the
  // rate changes, the lever arm's velocity steps by dw x r: those frames are left out).
  YAML::Node root = perfectDrive();
  root["imu_units"].push_back(unit(2, {0, 0, 0}, {0, 0, 0}));
  root["imu_units"].push_back(unit(3, {10, -20, 35}, {0, 0, 0}));
  root["imu_units"].push_back(unit(4, {0, 0, 0}, {0.5, -0.3, 0.2}));
  const auto config = parse(root);
  ASSERT_EQ(config.extra_imu_sensor_ids, (std::vector<std::uint32_t>{2, 3, 4}));
  const Eigen::Matrix3d c_u_b =
      navbus::core::dcmFromEuler(Eigen::Vector3d(10, -20, 35) * navbus::units::kDeg).transpose();
  const Eigen::Vector3d r(0.5, -0.3, 0.2);
  ScenarioSource src(config.scenario);
  int turning = 0;
  Eigen::Vector3d previous_w = Eigen::Vector3d::Zero();
  for (int k = 0; k < 60000; ++k) {
    const SensorFrame f = src.next();
    ASSERT_EQ(f.extra_imus.size(), 3u);
    const auto& primary = f.increment;
    const double T = primary.interval_s;
    EXPECT_LT((f.extra_imus[0].increment.delta_angle_b_rad - primary.delta_angle_b_rad).norm(),
              1e-15);
    EXPECT_LT((f.extra_imus[0].increment.delta_vel_b_mps - primary.delta_vel_b_mps).norm(), 1e-13);
    EXPECT_LT(
        (f.extra_imus[1].increment.delta_angle_b_rad - c_u_b * primary.delta_angle_b_rad).norm(),
        1e-15);
    EXPECT_LT((f.extra_imus[1].increment.delta_vel_b_mps - c_u_b * primary.delta_vel_b_mps).norm(),
              1e-13);
    const Eigen::Vector3d w = primary.delta_angle_b_rad / T;
    const Eigen::Vector3d dw = w - previous_w;
    previous_w = w;
    const Eigen::Vector3d centripetal = w.cross(w.cross(r));
    // In the turns (the centripetal term measurable), where the rate holds (dw x r negligible).
    if (w.norm() < 0.05 || dw.cross(r).norm() / T > 0.01 * centripetal.norm()) continue;
    ++turning;
    const Eigen::Vector3d extra_f =
        (f.extra_imus[2].increment.delta_vel_b_mps - primary.delta_vel_b_mps) / T;
    EXPECT_LT((extra_f - centripetal).norm(), 0.1 * centripetal.norm() + 1e-4)
        << "frame " << k << ": " << extra_f.transpose() << " against " << centripetal.transpose();
  }
  EXPECT_GT(turning, 100);
}

TEST(ImuUnits, AFaultAddressedToAUnitChangesThatUnitOnly) {
  // Given the drive with two further units (sensors 2 and 3) of the scenario's own grade, when a
  // 10 deg/h gyro-x step is addressed to sensor 3 from 20 s, then the primary's and sensor 2's
  // increments are bit for bit those of the fault-free run, and sensor 3's differ by the step
  // times the interval on its x axis after 20 s, and by nothing before (the frames around the
  // onset, partly faulty, aside).
  YAML::Node root = scenarioYaml();
  root["imu_units"].push_back(unit(2, {0, 0, 90}, {0.1, 0, 0}));
  root["imu_units"].push_back(unit(3, {0, 45, 0}, {0, 0.1, 0}));
  root["faults"] = YAML::Node(YAML::NodeType::Sequence);
  const auto clean = parse(root);
  YAML::Node fault = imuFault("imu_bias_step", 20.0, "gyro", "x", 3);
  fault["magnitude_deg_per_h"] = 10.0;
  root["faults"].push_back(fault);
  const auto faulty = parse(root);
  ScenarioSource a(clean.scenario), b(faulty.scenario);
  const double step = 10.0 * navbus::units::kDegPerHour;
  for (int k = 0; k < 4000; ++k) {
    const SensorFrame fa = a.next(), fb = b.next();
    ASSERT_EQ(fa.increment.delta_angle_b_rad, fb.increment.delta_angle_b_rad);
    ASSERT_EQ(fa.extra_imus[0].increment.delta_angle_b_rad,
              fb.extra_imus[0].increment.delta_angle_b_rad);
    const double t = 1e-9 * static_cast<double>(fa.time_ns - clean.scenario.start_time_ns);
    const double T = fa.increment.interval_s;
    const Eigen::Vector3d d =
        fb.extra_imus[1].increment.delta_angle_b_rad - fa.extra_imus[1].increment.delta_angle_b_rad;
    if (std::abs(t - 20.0) <= 2.0 * T) continue;  // the frames around the onset: partly faulty
    EXPECT_NEAR(d.x(), t < 20.0 ? 0.0 : step * T, 1e-15) << "t = " << t;
    EXPECT_EQ(d.y(), 0.0);
    EXPECT_EQ(d.z(), 0.0);
    if (t > 20.0) {
      EXPECT_NEAR(fb.extra_imus[1].truth_gyro_bias_u_radps.x() -
                      fa.extra_imus[1].truth_gyro_bias_u_radps.x(),
                  step, 1e-18);
    }
  }
}

TEST(ImuUnits, ABiasRampGrowsAtItsSlopeUpToItsSaturation) {
  YAML::Node root = perfectDrive();
  root["imu_units"].push_back(unit(2, {0, 0, 0}, {0, 0, 0}));
  YAML::Node ramp = imuFault("imu_bias_ramp", 10.0, "gyro", "z", 2);
  ramp["slope_deg_per_h_per_s"] = 0.5;
  ramp["saturation_deg_per_h"] = 20.0;
  root["faults"].push_back(ramp);
  const auto c = parse(root);
  const auto& faults = c.scenario.faults;
  const double dph = navbus::units::kDegPerHour;
  EXPECT_EQ(faults.gyroBias(9.0, 1).z(), 0.0);
  EXPECT_NEAR(faults.gyroBias(30.0, 1).z(), 10.0 * dph, 1e-15);
  EXPECT_NEAR(faults.gyroBias(100.0, 1).z(), 20.0 * dph, 1e-15);
  EXPECT_EQ(faults.gyroBias(100.0, 0).z(), 0.0);  // the scenario's own IMU is not faulty
}

TEST(ImuUnits, AScaleFactorStepReachesItsUnitsAxisOnly) {
  // Given the drive with a perfect primary IMU and two perfect units (sensors 2 and 3 as the
  // primary), when sensor 2's z gyro reads 1000 ppm long from 20 s, then its z increments are
  // 1.001 times the primary's after 20 s and equal before, its x axis and sensor 3 unchanged.
  YAML::Node root = perfectDrive();
  root["imu_units"].push_back(unit(2, {0, 0, 0}, {0, 0, 0}));
  root["imu_units"].push_back(unit(3, {0, 0, 0}, {0, 0, 0}));
  YAML::Node scale = imuFault("imu_scale_factor_step", 20.0, "gyro", "z", 2);
  scale["magnitude_ppm"] = 1000.0;
  root["faults"].push_back(scale);
  const auto c = parse(root);
  ScenarioSource src(c.scenario);
  int turning = 0;
  for (int k = 0; k < 6000; ++k) {
    const SensorFrame f = src.next();
    const double t = 1e-9 * static_cast<double>(f.time_ns - c.scenario.start_time_ns);
    const double T = f.increment.interval_s;
    if (std::abs(t - 20.0) <= 2.0 * T) continue;  // the frames around the onset
    const Eigen::Vector3d& primary = f.increment.delta_angle_b_rad;
    const Eigen::Vector3d& faulty = f.extra_imus[0].increment.delta_angle_b_rad;
    EXPECT_NEAR(faulty.z(), (t < 20.0 ? 1.0 : 1.001) * primary.z(), 1e-15) << "t = " << t;
    EXPECT_EQ(faulty.x(), primary.x());
    EXPECT_EQ(f.extra_imus[1].increment.delta_angle_b_rad, primary);
    turning += t > 20.0 && std::abs(primary.z()) > 1e-4 ? 1 : 0;
  }
  EXPECT_GT(turning, 50);  // the check saw the scale factor at work
}

TEST(ImuUnits, ANoiseIncreaseMultipliesTheAxisNoiseAndLeavesTheRestBitForBit) {
  // Given the drive's own IMU grade on two units (sensors 2 and 3), when sensor 3's x gyro's
  // white noise density is multiplied by 4 from 0 s, then the spread of its x increments about
  // sensor 2's grows about 4-fold against the y axis's (sqrt((16 + 1) / 2) = 2.9 of the
  // difference's), sensor 2 and the primary are bit for bit the fault-free run's.
  YAML::Node root = scenarioYaml();
  root["vibration"] = YAML::Node(YAML::NodeType::Map);
  root["vibration"]["enabled"] = false;
  root["imu_units"].push_back(unit(2, {0, 0, 0}, {0, 0, 0}));
  root["imu_units"].push_back(unit(3, {0, 0, 0}, {0, 0, 0}));
  root["faults"] = YAML::Node(YAML::NodeType::Sequence);
  const auto clean = parse(root);
  YAML::Node noise = imuFault("imu_noise_increase", 0.0, "gyro", "x", 3);
  noise["factor"] = 4.0;
  root["faults"].push_back(noise);
  const auto faulty = parse(root);
  ScenarioSource a(clean.scenario), b(faulty.scenario);
  // Successive differences of the units' difference: the biases (constant over a step) cancel.
  double sum_x = 0.0, sum_y = 0.0;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const SensorFrame fa = a.next(), fb = b.next();
    ASSERT_EQ(fa.increment.delta_angle_b_rad, fb.increment.delta_angle_b_rad);
    ASSERT_EQ(fa.extra_imus[0].increment.delta_angle_b_rad,
              fb.extra_imus[0].increment.delta_angle_b_rad);
    const Eigen::Vector3d d =
        fb.extra_imus[1].increment.delta_angle_b_rad - fb.extra_imus[0].increment.delta_angle_b_rad;
    if (k > 0) {
      sum_x += std::pow(d.x() - previous.x(), 2);
      sum_y += std::pow(d.y() - previous.y(), 2);
    }
    previous = d;
  }
  const double ratio = std::sqrt(sum_x / sum_y);
  EXPECT_NEAR(ratio, std::sqrt((16.0 + 1.0) / 2.0), 0.1 * std::sqrt(17.0 / 2.0)) << ratio;
}

TEST(ImuUnits, RefusesIdsItCannotPlaceNamingThem) {
  YAML::Node duplicate = perfectDrive();
  duplicate["ids"]["imu"] = 5;
  duplicate["imu_units"].push_back(unit(5, {0, 0, 0}, {0, 0, 0}));
  try {
    parse(duplicate);
    FAIL() << "a unit with the scenario IMU's id was accepted";
  } catch (const navbus::bus::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("imu_units[0].sensor_id = 5"), std::string::npos)
        << e.what();
  }
  YAML::Node unknown = perfectDrive();
  unknown["imu_units"].push_back(unit(2, {0, 0, 0}, {0, 0, 0}));
  unknown["faults"].push_back(imuFault("sensor_stuck", 1.0, "accelerometer", "y", 7));
  try {
    parse(unknown);
    FAIL() << "a fault on an unknown IMU was accepted";
  } catch (const navbus::bus::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("faults[0].sensor_id = 7"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1, 2"), std::string::npos) << e.what();
  }
}

// `navbus-sensor-sim --files`: the further IMU units' increments and the further receivers'
// epochs go to their own files, each row naming its id, the same numbers the bus would carry
// (they were left out before: nothing said so).
TEST(ImuUnits, TheFilesHoldEveryFurtherUnitAndReceiver) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("navbus-files-units-" + std::to_string(::getpid()));
  for (const char* name : {"seed000_triplex.yaml", "seed000_dual_receivers.yaml"}) {
    const navbus::sensor_sim::SimConfig config = navbus::sensor_sim::parseSimConfig(
        navbus::bus::loadYamlFile(std::string(navbus::test_paths::scenarioDir()) + "/" + name));
    std::vector<SensorFrame> frames;
    {
      navbus::sensor_sim::FileWriter files(dir, config.scenario, config.extra_imu_sensor_ids,
                                           config.extra_gnss_receiver_ids);
      ScenarioSource source(config.scenario);
      for (int k = 0; k < 300; ++k) {
        frames.push_back(source.next());
        files.write(frames.back());
      }
      EXPECT_EQ(files.counts().unit_increments, 300 * config.extra_imu_sensor_ids.size());
      EXPECT_EQ(files.counts().receiver_epochs, 3 * config.extra_gnss_receiver_ids.size());
    }
    const SensorFrame& last = frames.back();
    if (!config.extra_imu_sensor_ids.empty()) {
      const navbus::records::CsvTable t = navbus::records::readCsv(dir / "imu_units.csv");
      ASSERT_EQ(t.rows.size(), 300 * config.extra_imu_sensor_ids.size());
      const auto& row = t.rows.back();  // the last unit's last increment
      EXPECT_EQ(std::stoul(row[t.column("sensor_id")]), config.extra_imu_sensor_ids.back());
      EXPECT_EQ(std::stoll(row[t.column("time_gps_ns")]), last.time_ns);
      EXPECT_EQ(std::stod(row[t.column("delta_angle_z_rad")]),
                last.extra_imus.back().increment.delta_angle_b_rad.z());
    }
    if (!config.extra_gnss_receiver_ids.empty()) {
      const navbus::records::CsvTable t = navbus::records::readCsv(dir / "gnss_receivers.csv");
      auto with_gnss = frames.rbegin();
      while (!with_gnss->has_gnss) ++with_gnss;
      const auto& epoch = with_gnss->extra_gnss.back();
      ASSERT_FALSE(epoch.satellites.empty());
      const auto& row = t.rows.back();
      EXPECT_EQ(std::stoul(row[t.column("receiver_id")]), config.extra_gnss_receiver_ids.back());
      EXPECT_EQ(std::stod(row[t.column("pseudorange_m")]), epoch.satellites.back().pseudorange_m);
    }
    std::filesystem::remove_all(dir);
  }
}
