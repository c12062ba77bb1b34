// The fault manager's cross-receiver detector (receiver_detector.hpp): its configuration (the
// receivers named by id, refusals naming the field), the alignment of the receivers' epochs
// whatever order they arrive in (a DDS reader hands out one receiver's backlog before the
// next's), and a clock-jump decision naming the receiver.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "fault_recorder.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/receiver_detector.hpp"

namespace fm = navbus::fault_manager;
namespace nc = navbus::core;

namespace {

constexpr const char* kTwoReceivers = R"(
receivers:
  enabled: true
  units:
    - {receiver_id: 1, antenna_b_m: [0, 0, 0]}
    - {receiver_id: 2, antenna_b_m: [-1.5, 0, -0.3]}
)";

using Recorder = fm::test::Recorder;

/// Receiver `id`'s epoch at second t: five satellites, 3 m noise, its clock (+ `jump_m`), and
/// satellite `long_sv` `long_m` long.
navbus::GnssObservationEpoch epoch(std::uint32_t id, int t, std::mt19937_64& rng,
                                   double jump_m = 0.0, int long_sv = 0, double long_m = 0.0) {
  const nc::earth::Geodetic p{0.637, 2.225, 1000.0};
  const Eigen::Vector3d rx = nc::earth::geodeticToEcef(p);
  const Eigen::Matrix3d C_n_e = nc::earth::C_n_e(p.latitude_rad, p.longitude_rad);
  std::normal_distribution<double> noise(0.0, 3.0);
  navbus::GnssObservationEpoch e;
  e.receiver_id(id);
  e.seq(static_cast<std::uint64_t>(t + 1));
  e.time_gps_ns(1400000000000000000ull + static_cast<std::uint64_t>(t) * 1000000000ull);
  const double clock = (id == 1 ? 3000.0 : -12000.0) + jump_m;
  for (int k = 0; k < 5; ++k) {
    const double az = 1.2 * k, el = 0.3 + 0.2 * k;
    const Eigen::Vector3d sat =
        rx + C_n_e *
                 Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                 -std::sin(el)) *
                 2.02e7;
    navbus::GnssSatelliteMeasurement m;
    m.sv_id(static_cast<std::uint16_t>(k + 1));
    m.pseudorange_m((sat - rx).norm() + clock + noise(rng) + (k + 1 == long_sv ? long_m : 0.0));
    m.pseudorange_rate_mps(0.0);
    for (int i = 0; i < 3; ++i) m.sat_pos_ecef_m()[static_cast<std::size_t>(i)] = sat[i];
    m.pseudorange_sigma_m(3.0);
    m.pseudorange_rate_sigma_mps(0.05);
    m.valid(true);
    e.satellites().push_back(m);
  }
  return e;
}

}  // namespace

TEST(ReceiverDetector, RefusesAConfigurationWithOneReceiverNamingTheField) {
  // Given `receivers:` with one unit, or an id twice, then the configuration is refused naming
  // receivers.units.
  const std::string one = R"(
receivers: {enabled: true, units: [{receiver_id: 1, antenna_b_m: [0, 0, 0]}]})";
  try {
    fm::parseFaultManagerConfig(YAML::Load(one));
    FAIL() << "one receiver accepted";
  } catch (const navbus::bus::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("receivers.units"), std::string::npos) << e.what();
  }
  const std::string twice = R"(
receivers: {enabled: true, units: [{receiver_id: 1, antenna_b_m: [0, 0, 0]},
                                   {receiver_id: 1, antenna_b_m: [1, 0, 0]}]})";
  try {
    fm::parseFaultManagerConfig(YAML::Load(twice));
    FAIL() << "an id twice accepted";
  } catch (const navbus::bus::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("receivers.units[1].receiver_id 1"), std::string::npos)
        << e.what();
  }
}

TEST(ReceiverDetector, AlignsABacklogOfOneReceiverBeforeTheOtherAndNamesAClockJump) {
  // Given two receivers, when receiver 2's 300 epochs all arrive before receiver 1's (a DDS
  // reader's backlog of one instance), then every time is tested (none incomplete or late);
  // and when receiver 1's clock jumps 1 ms at second 200, the one decision names receiver 1's
  // clock at that second, and its command compensates receiver 1's clock by the jump from the
  // instant before that epoch (so that a filter fuses the epoch after it).
  const fm::FaultManagerConfig config = fm::parseFaultManagerConfig(YAML::Load(kTwoReceivers));
  fm::ReceiverDetector detector(config.receivers);
  Recorder out;
  std::mt19937_64 rng(5);
  std::vector<navbus::GnssObservationEpoch> first, second;
  const double jump = 1e-3 * nc::earth::kSpeedOfLight_mps;
  for (int t = 0; t < 300; ++t) {
    second.push_back(epoch(2, t, rng));
    first.push_back(epoch(1, t, rng, t >= 200 ? jump : 0.0));
  }
  for (const auto& e : second) detector.onEpoch(e, out);
  for (const auto& e : first) detector.onEpoch(e, out);
  const fm::ReceiverDetector::Counters& c = detector.counters();
  EXPECT_EQ(c.tested, 300u);
  EXPECT_EQ(c.incomplete, 0u);
  EXPECT_EQ(c.late, 0u);
  ASSERT_EQ(out.decisions.size(), 1u) << detector.summary();
  const navbus::FaultDecision& d = out.decisions[0];
  EXPECT_EQ(d.source(), navbus::SOURCE_RECEIVER_CLOCK);
  EXPECT_EQ(d.sensor_id(), 1u);
  EXPECT_EQ(d.time_gps_ns(), 1400000200000000000ull);
  EXPECT_NEAR(d.magnitude(), jump, 30.0);
  ASSERT_EQ(out.commands.size(), 1u);
  const navbus::FilterCommand& cmd = out.commands[0];
  EXPECT_EQ(cmd.kind(), navbus::CMD_COMPENSATE_BIAS);
  EXPECT_EQ(cmd.sensor(), navbus::SOURCE_RECEIVER_CLOCK);
  EXPECT_EQ(cmd.sensor_id(), 1u);
  EXPECT_EQ(cmd.decision_id(), d.decision_id());
  EXPECT_EQ(cmd.time_gps_ns(), 1400000200000000000ull - 1u);
  EXPECT_EQ(cmd.onset_time_gps_ns(), 0u) << "applied at its own time, not by restoring";
  EXPECT_EQ(cmd.bias(), d.magnitude());
  // Its sigma is the jump's: |v| / sqrt(v^2 / var v); the 3 m ranges give a few metres.
  EXPECT_GT(cmd.bias_sigma(), 0.5);
  EXPECT_LT(cmd.bias_sigma(), 30.0);
  EXPECT_EQ(detector.testedUpToNs(), 1400000299000000000);
  EXPECT_TRUE(out.kept_out.empty()) << "a clock jump keeps no satellite out";
}

TEST(ReceiverDetector, ASatelliteOneReceiverMeasuresWrongIsExcludedFromBothAndKeptOutOfTheGlr) {
  // Given two receivers, when receiver 2's satellite 3 reads 100 m long from second 100, then
  // the one decision names satellite 3 (ambiguous between the receivers: two cannot say whose
  // measurement is wrong), its command excludes it from every receiver, and the detector tells
  // the pipeline to keep it out of the other tests (the GLR of a filter fusing both receivers).
  const fm::FaultManagerConfig config = fm::parseFaultManagerConfig(YAML::Load(kTwoReceivers));
  fm::ReceiverDetector detector(config.receivers);
  Recorder out;
  std::mt19937_64 rng(7);
  for (int t = 0; t < 200; ++t) {
    detector.onEpoch(epoch(1, t, rng), out);
    detector.onEpoch(epoch(2, t, rng, 0.0, 3, t >= 100 ? 100.0 : 0.0), out);
  }
  ASSERT_EQ(out.decisions.size(), 1u) << detector.summary();
  const navbus::FaultDecision& d = out.decisions[0];
  EXPECT_EQ(d.source(), navbus::SOURCE_SATELLITE);
  EXPECT_EQ(d.sv_id(), 3u);
  EXPECT_TRUE(d.ambiguous());
  EXPECT_GE(d.time_gps_ns(), 1400000100000000000ull);
  EXPECT_LT(d.time_gps_ns(), 1400000110000000000ull);
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(out.commands[0].kind(), navbus::CMD_EXCLUDE_SATELLITE);
  EXPECT_EQ(out.commands[0].scope(), navbus::SCOPE_ALL);
  EXPECT_EQ(out.kept_out, std::vector<int>{3});
}

TEST(ReceiverDetector, AReceiverGoneIsNotWaitedForBeyondItsLastEpochAndIsAgainWhenItReturns) {
  // Given two receivers, receiver 2 silent after second 99 while receiver 1 goes on: its times
  // wait for receiver 2 (judged up to 99 s); once receiver 2 is declared gone after 99 s, the
  // waiting times are settled (one receiver is no pair: untested, counted incomplete) and the
  // judgement reaches 149 s. When receiver 2 returns at 150 s it is waited for again: every
  // later time is tested with both, and receiver 1's clock jump at 250 s is named.
  const fm::FaultManagerConfig config = fm::parseFaultManagerConfig(YAML::Load(kTwoReceivers));
  fm::ReceiverDetector detector(config.receivers);
  Recorder out;
  std::mt19937_64 rng(7);
  const double jump = 1e-3 * nc::earth::kSpeedOfLight_mps;
  constexpr std::int64_t kT0 = 1400000000000000000;
  constexpr std::int64_t kSecond = 1000000000;
  for (int t = 0; t < 150; ++t) {
    detector.onEpoch(epoch(1, t, rng), out);
    if (t < 100) detector.onEpoch(epoch(2, t, rng), out);
  }
  EXPECT_EQ(detector.testedUpToNs(), kT0 + 99 * kSecond);
  detector.receiverGone(2, kT0 + 99 * kSecond, out);
  detector.receiverGone(2, kT0 + 99 * kSecond, out);  // told again by another reader: no change
  EXPECT_EQ(detector.testedUpToNs(), kT0 + 149 * kSecond);
  EXPECT_EQ(detector.counters().incomplete, 50u);
  EXPECT_EQ(detector.counters().tested, 100u);
  for (int t = 150; t < 300; ++t) {
    detector.onEpoch(epoch(2, t, rng), out);
    detector.onEpoch(epoch(1, t, rng, t >= 250 ? jump : 0.0), out);
  }
  EXPECT_EQ(detector.counters().tested, 250u);
  EXPECT_EQ(detector.counters().incomplete, 50u);
  EXPECT_EQ(detector.testedUpToNs(), kT0 + 299 * kSecond);
  ASSERT_EQ(out.decisions.size(), 1u) << detector.summary();
  EXPECT_EQ(out.decisions[0].sensor_id(), 1u);
  EXPECT_EQ(out.decisions[0].time_gps_ns(), static_cast<std::uint64_t>(kT0 + 250 * kSecond));
}
