// The lanes' comparison of two suspect units (nav_filter/suspect_lanes.hpp): the reference taken
// before the onset whether the selection reaches the onset before or after the pair of
// suspects arrives, the unit whose lane learns the step named at the first time the evidence
// holds, a mounted unit's axis read in its own axes, a lane failing its consistency test alone.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/nav_filter/suspect_lanes.hpp"

namespace nf = navbus::nav_filter;
using navbus::units::kDegPerHour;

namespace {

constexpr std::int64_t kT0 = 1'000'000'000'000;  ///< [ns]
constexpr std::int64_t kStepNs = 100'000'000;    ///< solutions at 10 Hz
constexpr std::int64_t kOnsetNs = kT0 + 50 * kStepNs;

/// A lane's solution with its gyro bias estimate [rad/s, body] and 1-sigma on every axis.
navbus::NavigationSolution solution(std::int64_t t_ns, const Eigen::Vector3d& gyro_b,
                                    double sigma) {
  navbus::NavigationSolution s;
  s.time_gps_ns(static_cast<std::uint64_t>(t_ns));
  for (std::size_t i = 0; i < 3; ++i) {
    s.gyro_bias_b_radps()[i] = gyro_b[static_cast<Eigen::Index>(i)];
    s.gyro_bias_sigma_b_radps()[i] = sigma;
    s.accel_bias_sigma_b_mps2()[i] = 1e-4;
  }
  s.mode(navbus::MODE_TIGHTLY_COUPLED);
  return s;
}

std::vector<nf::LaneUnit> parallelUnits() {
  nf::LaneUnit a, b;
  a.sensor_id = 1;
  b.sensor_id = 2;
  return {a, b};
}

/// Lane 1 (unit 2) learns a 10 deg/h step on its x gyro from the onset (a 20 s time constant);
/// lane 0 holds still. Selections from `from` to `to`; the naming, if any.
std::optional<nf::SuspectLanes::Named> select(
    nf::SuspectLanes& s, int from, int to,
    const Eigen::Matrix3d& c_b_u2 = Eigen::Matrix3d::Identity()) {
  for (int k = from; k <= to; ++k) {
    const std::int64_t t = kT0 + k * kStepNs;
    const double after_s = 1e-9 * static_cast<double>(std::max<std::int64_t>(t - kOnsetNs, 0));
    const double learnt = 10.0 * kDegPerHour * (1.0 - std::exp(-after_s / 20.0));
    const auto a = solution(t, Eigen::Vector3d(0.2, 0.1, 0.0) * kDegPerHour, 0.3 * kDegPerHour);
    // Unit 2's x axis is c_b_u2's first column in body axes.
    const auto b = solution(t, c_b_u2 * Eigen::Vector3d(-0.4 * kDegPerHour + learnt, 0.0, 0.0),
                            0.3 * kDegPerHour);
    if (auto n = s.atSelection(t, {&a, &b})) return n;
  }
  return std::nullopt;
}

nf::SuspectLanes::Suspect suspect(int lane) {
  return {7, lane, false, 0, kOnsetNs};
}

}  // namespace

TEST(SuspectLanes, TheLaneThatLearnsTheStepIsNamedWhetherTheSelectionPassedTheOnsetOrNot) {
  // Given the pair of suspects before the selection reached the onset, or after it had passed
  // it by 3 s (the reference then comes from the selections kept), then unit 2 (lane 1) is
  // named at the same time: 2 h = 23.9 takes a change of 4.9 s = 2.07 deg/h (s^2 = 2 x 0.3^2),
  // 4.6 s after the onset.
  std::optional<std::int64_t> named_at;
  for (const int passed : {0, 80}) {
    nf::SuspectLanes s(parallelUnits(), navbus::core::LaneEvidenceConfig{});
    ASSERT_FALSE(select(s, 0, passed));
    s.onSuspect(suspect(1));
    EXPECT_EQ(s.counters().questions, 0u);  // the first of the pair waits for the second
    s.onSuspect(suspect(0));
    EXPECT_EQ(s.counters().questions, 1u);
    const auto n = passed == 0 ? select(s, 1, 2000) : select(s, passed + 1, 2000);
    ASSERT_TRUE(n) << s.summary();
    EXPECT_EQ(n->suspect.lane, 1);
    EXPECT_EQ(n->evidence.kind, navbus::core::LaneEvidenceKind::kBiasMoved);
    EXPECT_NEAR(n->evidence.bias_change / kDegPerHour, 2.07, 0.1);
    EXPECT_NEAR(1e-9 * static_cast<double>(n->time_ns - kOnsetNs), 4.7, 0.15);
    if (named_at) {
      EXPECT_EQ(*named_at, n->time_ns);
    }
    named_at = n->time_ns;
    EXPECT_EQ(s.counters().named, 1u);
    EXPECT_FALSE(select(s, 2001, 2100));  // decided once
  }
}

TEST(SuspectLanes, AMountedUnitsAxisIsReadInItsOwnAxes) {
  // Unit 2 turned 90 deg in yaw: its x axis is the body's y. Its lane estimates in body axes;
  // the suspect names the unit's x axis: the step is found there.
  std::vector<nf::LaneUnit> units = parallelUnits();
  units[1].c_b_u =
      navbus::core::dcmFromEuler(Eigen::Vector3d(0.0, 0.0, 90.0 * navbus::units::kDeg));
  nf::SuspectLanes s(units, navbus::core::LaneEvidenceConfig{});
  s.onSuspect(suspect(1));
  s.onSuspect(suspect(0));
  const auto n = select(s, 0, 2000, units[1].c_b_u);
  ASSERT_TRUE(n);
  EXPECT_EQ(n->suspect.lane, 1);
  EXPECT_NEAR(1e-9 * static_cast<double>(n->time_ns - kOnsetNs), 4.7, 0.15);
}

TEST(SuspectLanes, ALaneFailingItsOwnConsistencyTestAloneIsNamed) {
  // Neither estimate moves, but lane 0's consistency test fails after the onset: unit 1 named.
  nf::SuspectLanes s(parallelUnits(), navbus::core::LaneEvidenceConfig{});
  s.onSuspect(suspect(0));
  s.onSuspect(suspect(1));
  std::optional<nf::SuspectLanes::Named> n;
  for (int k = 0; k < 200 && !n; ++k) {
    const std::int64_t t = kT0 + k * kStepNs;
    auto a = solution(t, Eigen::Vector3d::Zero(), 0.3 * kDegPerHour);
    const auto b = solution(t, Eigen::Vector3d::Zero(), 0.3 * kDegPerHour);
    if (k >= 120) a.active_fault_flags(navbus::FAULT_FILTER_INCONSISTENT);
    n = s.atSelection(t, {&a, &b});
  }
  ASSERT_TRUE(n);
  EXPECT_EQ(n->suspect.lane, 0);
  EXPECT_EQ(n->evidence.kind, navbus::core::LaneEvidenceKind::kLaneInconsistent);
  EXPECT_EQ(n->time_ns, kT0 + 120 * kStepNs);
}
