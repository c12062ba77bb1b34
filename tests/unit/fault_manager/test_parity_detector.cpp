// The fault manager's parity detector (parity_detector.hpp): its configuration (units named by
// sensor id, refusals naming the field), the alignment of the units' increments whatever order
// the units arrive in (a DDS reader takes one instance's backlog before the next's), a lost
// increment (counted, the window restarted), and a decision naming the unit, its axis and the
// command for it.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "fault_recorder.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/parity_detector.hpp"

namespace fm = navbus::fault_manager;

namespace {

constexpr const char* kTriplexParity = R"(
parity:
  enabled: true
  imu_rate_hz: 100
  units:
    - {sensor_id: 11, mounting_rpy_deg: [0, 0, 0], lever_arm_b_m: [0, 0, 0],
       gyro_arw_deg_per_sqrth: 0.001, accel_noise_ug_per_sqrthz: 10}
    - {sensor_id: 12, mounting_rpy_deg: [35, 0, 45], lever_arm_b_m: [0, 0, 0],
       gyro_arw_deg_per_sqrth: 0.001, accel_noise_ug_per_sqrthz: 10}
    - {sensor_id: 13, mounting_rpy_deg: [0, -35, -45], lever_arm_b_m: [0, 0, 0],
       gyro_arw_deg_per_sqrth: 0.001, accel_noise_ug_per_sqrthz: 10}
  reference_s: 5
)";

fm::FaultManagerConfig parityConfig(const std::string& yaml = kTriplexParity) {
  return fm::parseFaultManagerConfig(YAML::Load(yaml));
}

using Recorder = fm::test::Recorder;

/// A level, still body sensed by the three units (their axes: rows of the mountings), white
/// noise of the configured grade; unit 12's y gyro gains `step_radps` from sample `step_from`.
std::vector<navbus::ImuIncrement> stillBodyIncrements(const fm::ParityDetectorConfig& c,
                                                      int samples, int step_from = -1,
                                                      double step_radps = 0.0) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d f_b(0.0, 0.0, -9.80665), w_b(5e-5, 0.0, -5e-5);
  std::vector<navbus::ImuIncrement> out;
  for (int k = 1; k <= samples; ++k) {
    for (std::size_t u = 0; u < c.units.size(); ++u) {
      const auto& unit = c.units[u];
      Eigen::Vector3d w_u = unit.c_u_b * w_b;
      if (u == 1 && step_from >= 0 && k >= step_from) w_u.y() += step_radps;
      navbus::ImuIncrement m;
      m.sensor_id(c.sensor_ids[u]);
      m.seq(static_cast<std::uint64_t>(k));
      m.time_gps_ns(1'000'000'000'000ull + static_cast<std::uint64_t>(k) * 10'000'000ull);
      m.interval_ns(10'000'000u);
      const Eigen::Vector3d f_u = unit.c_u_b * f_b;
      for (int i = 0; i < 3; ++i) {
        m.delta_angle_b_rad()[i] = w_u[i] * 0.01 + unit.gyro_sigma_rad * n(rng);
        m.delta_vel_b_mps()[i] = f_u[i] * 0.01 + unit.accel_sigma_mps * n(rng);
      }
      out.push_back(m);
    }
  }
  return out;
}

/// The same increments, one unit's whole backlog after the other's (in blocks of `block`).
std::vector<navbus::ImuIncrement> unitByUnit(const std::vector<navbus::ImuIncrement>& in,
                                             std::size_t block) {
  std::vector<navbus::ImuIncrement> out;
  const std::size_t per_unit = in.size() / 3;
  for (std::size_t start = 0; start < per_unit; start += block)
    for (std::size_t u = 0; u < 3; ++u)
      for (std::size_t k = start; k < std::min(per_unit, start + block); ++k)
        out.push_back(in[3 * k + (2 - u)]);  // the last unit first
  return out;
}

}  // namespace

TEST(ParityDetector, IsolatesTheUnitWhateverOrderItsIncrementsArriveIn) {
  // Given three units (ids 11, 12, 13) on a still body and a 5 deg/h step on unit 12's y gyro
  // from sample 1000, when the increments come interleaved, or one unit's 700-sample backlog
  // after another's (the last unit first), then both runs decide the same: unit 12, gyro y, not
  // ambiguous, the command failing that unit's axis; no time is dropped.
  const fm::FaultManagerConfig config = parityConfig();
  const auto data =
      stillBodyIncrements(config.parity, 1400, 1000, 5.0 * navbus::units::kDegPerHour);
  Recorder a, b;
  fm::ParityDetector interleaved(config.parity), backlog(config.parity);
  for (const auto& m : data) interleaved.onIncrement(m, a);
  for (const auto& m : unitByUnit(data, 700)) backlog.onIncrement(m, b);
  ASSERT_EQ(a.decisions.size(), 1u) << interleaved.summary();
  ASSERT_EQ(b.decisions.size(), 1u) << backlog.summary();
  const navbus::FaultDecision& d = a.decisions[0];
  EXPECT_EQ(d.detector(), "parity");
  EXPECT_EQ(d.sensor_id(), 12u);
  EXPECT_EQ(d.source(), navbus::SOURCE_GYRO);
  EXPECT_EQ(d.axis(), 1);
  EXPECT_FALSE(d.ambiguous());
  EXPECT_EQ(d.candidates()[0].sensor_id(), 12u);
  EXPECT_EQ(b.decisions[0].time_gps_ns(), d.time_gps_ns());
  EXPECT_EQ(b.decisions[0].test_statistic(), d.test_statistic());
  ASSERT_EQ(a.commands.size(), 1u);
  EXPECT_EQ(a.commands[0].kind(), navbus::CMD_FAIL_SENSOR_AXIS);
  EXPECT_EQ(a.commands[0].sensor_id(), 12u);
  EXPECT_EQ(a.commands[0].axis(), 1);
  EXPECT_EQ(interleaved.counters().samples, 1400u);
  EXPECT_EQ(backlog.counters().samples, 1400u);
  EXPECT_EQ(backlog.counters().incomplete, 0u);
}

TEST(ParityDetector, AUnitWhoseStartWasNotReceivedIsCountedAndItsTimesDropped) {
  // Given the fault-free still body, when the reader never got unit 12's first 5 increments
  // (a reader that matched the unit's writer after it began), then the detector counts the 5
  // from the first sequence number it took and says so, those 5 times are dropped as without
  // every unit, and the rest is tested.
  const fm::FaultManagerConfig config = parityConfig();
  auto data = stillBodyIncrements(config.parity, 1000);
  std::vector<navbus::ImuIncrement> late_start;
  for (const auto& m : data)
    if (!(m.sensor_id() == 12u && m.seq() <= 5)) late_start.push_back(m);
  Recorder out;
  fm::ParityDetector detector(config.parity);
  for (const auto& m : late_start) detector.onIncrement(m, out);
  EXPECT_TRUE(out.decisions.empty());
  EXPECT_EQ(detector.counters().missed_at_start, 5u);
  EXPECT_EQ(detector.counters().incomplete, 5u);
  EXPECT_EQ(detector.counters().samples, 995u);
  EXPECT_NE(detector.summary().find("not received before a unit's first 5"), std::string::npos)
      << detector.summary();
}

TEST(ParityDetector, ALostIncrementDropsItsTimeCountedAndRestartsTheWindow) {
  // Given the fault-free still body, when unit 13's increment at sample 600 never comes (and an
  // increment of an unconfigured sensor and one at another interval do), then that time is
  // dropped once the unit has passed it, the window restarts, the others are counted, nothing
  // is decided.
  const fm::FaultManagerConfig config = parityConfig();
  auto data = stillBodyIncrements(config.parity, 1000);
  data.erase(data.begin() + 3 * 599 + 2);
  navbus::ImuIncrement other = data[0];
  other.sensor_id(99);
  navbus::ImuIncrement slow = data[1];
  slow.interval_ns(20'000'000u);
  data.insert(data.begin() + 10, other);
  data.insert(data.begin() + 11, slow);
  Recorder out;
  fm::ParityDetector detector(config.parity);
  for (const auto& m : data) detector.onIncrement(m, out);
  EXPECT_TRUE(out.decisions.empty());
  EXPECT_EQ(detector.counters().incomplete, 1u);
  EXPECT_EQ(detector.counters().samples, 999u);
  EXPECT_EQ(detector.counters().other_sensors, 1u);
  EXPECT_EQ(detector.counters().wrong_interval, 1u);
  EXPECT_NE(detector.summary().find("times without every unit 1"), std::string::npos)
      << detector.summary();
}

TEST(ParityDetector, ConfigurationErrorsNameTheField) {
  const auto refused = [](const std::string& yaml, const std::string& says) {
    try {
      parityConfig(yaml);
      ADD_FAILURE() << "accepted: " << yaml;
    } catch (const navbus::bus::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  std::string twice = kTriplexParity;
  twice.replace(twice.find("sensor_id: 13"), 13, "sensor_id: 12");
  refused(twice, "parity.units[2].sensor_id 12 is given twice");
  std::string noisy = kTriplexParity;
  noisy.replace(noisy.find("accel_noise_ug_per_sqrthz: 10}"), 30, "accel_noise_ug_per_sqrthz: -1}");
  refused(noisy, "accel_noise_ug_per_sqrthz");
  refused(std::string(kTriplexParity) + "  onsets: 0\n", "onsets is 0");
  refused(std::string(kTriplexParity) + "  window: 3\n", "window");
  refused("parity: {enabled: true, units: []}\n", "2 to 6");
}

TEST(ParityDetector, TwoParallelUnitsAreSuspectsUntilTheLanesNameOne) {
  // Given two parallel units (ids 11, 12) and a 5 deg/h step on unit 12's y gyro, then the
  // decision is ambiguous between the two y gyros, each candidate with its own magnitude
  // (opposite), and both are commanded to re-learn that bias and named as suspects (no axis
  // failed); when a lane solution of unit 12 says the lanes found it the faulty one of that
  // decision, then one decision "lanes" names unit 12 at that time, once; a lane naming
  // nothing, or another decision, changes nothing.
  const fm::FaultManagerConfig config = parityConfig(R"(
parity:
  enabled: true
  imu_rate_hz: 100
  units:
    - {sensor_id: 11, mounting_rpy_deg: [0, 0, 0], lever_arm_b_m: [0, 0, 0],
       gyro_arw_deg_per_sqrth: 0.001, accel_noise_ug_per_sqrthz: 10}
    - {sensor_id: 12, mounting_rpy_deg: [0, 0, 0], lever_arm_b_m: [0, 0, 0],
       gyro_arw_deg_per_sqrth: 0.001, accel_noise_ug_per_sqrthz: 10}
  reference_s: 5
)");
  const double step = 5.0 * navbus::units::kDegPerHour;
  Recorder r;
  fm::ParityDetector parity(config.parity);
  for (const auto& m : stillBodyIncrements(config.parity, 1400, 1000, step))
    parity.onIncrement(m, r);
  ASSERT_EQ(r.decisions.size(), 1u) << parity.summary();
  const navbus::FaultDecision d = r.decisions[0];
  EXPECT_TRUE(d.ambiguous());
  ASSERT_EQ(d.candidates().size(), 2u);
  const auto& c = d.candidates();
  EXPECT_EQ(c[0].sensor_id() + c[1].sensor_id(), 23u);
  const double on_12 = c[0].sensor_id() == 12 ? c[0].magnitude() : c[1].magnitude();
  const double on_11 = c[0].sensor_id() == 11 ? c[0].magnitude() : c[1].magnitude();
  EXPECT_NEAR(on_12, step, 0.2 * step);
  EXPECT_DOUBLE_EQ(on_11, -on_12);
  ASSERT_EQ(r.commands.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    const navbus::FilterCommand& cmd = r.commands[k];
    EXPECT_EQ(cmd.kind(), k < 2 ? navbus::CMD_RELEARN_BIAS : navbus::CMD_SUSPECT_SENSOR_AXIS);
    EXPECT_EQ(cmd.sensor_id(), c[k % 2].sensor_id());
    EXPECT_EQ(cmd.axis(), 1);
    EXPECT_EQ(cmd.decision_id(), d.decision_id());
    EXPECT_EQ(cmd.onset_time_gps_ns(), d.onset_time_gps_ns());
    if (k < 2) {
      EXPECT_GE(cmd.bias_sigma(), std::abs(on_12));
    }
  }
  navbus::LaneSolution lane;
  lane.vehicle_id(1);
  lane.lane_id(11);
  lane.solution().time_gps_ns(d.time_gps_ns() + 30'000'000'000ull);
  parity.onLaneSolution(lane, r);  // names nothing
  lane.lane_id(12);
  lane.named_faulty_for_decision(d.decision_id() + 7);
  parity.onLaneSolution(lane, r);  // another decision's
  EXPECT_EQ(r.decisions.size(), 1u);
  lane.named_faulty_for_decision(d.decision_id());
  parity.onLaneSolution(lane, r);
  parity.onLaneSolution(lane, r);  // and again: decided once
  ASSERT_EQ(r.decisions.size(), 2u);
  const navbus::FaultDecision& named = r.decisions[1];
  EXPECT_EQ(named.detector(), "lanes");
  EXPECT_FALSE(named.ambiguous());
  EXPECT_EQ(named.sensor_id(), 12u);
  EXPECT_EQ(named.axis(), 1);
  EXPECT_EQ(named.time_gps_ns(), lane.solution().time_gps_ns());
  EXPECT_EQ(named.onset_time_gps_ns(), d.onset_time_gps_ns());
  EXPECT_DOUBLE_EQ(named.magnitude(), on_12);
  EXPECT_EQ(named.candidates()[1].sensor_id(), 11u);
  EXPECT_EQ(r.commands.size(), 4u);  // the lanes acted already: nothing to command
  EXPECT_EQ(parity.counters().named_by_lanes, 1u);
}
