// The lane selector (core/filter/lane_selector.hpp): the first selection, hysteresis, the
// immediate switch away from an excluded lane, and reset deltas that equal the jump.
#include <gtest/gtest.h>

#include <vector>

#include <Eigen/Geometry>

#include "navbus/core/filter/lane_selector.hpp"
#include "navbus/core/math/earth.hpp"

namespace nc = navbus::core;

namespace {

nc::NavState state(double north_m, double east_m, double down_m, double yaw_rad) {
  nc::NavState s;
  s.position = nc::earth::offsetNed({0.9, 0.2, 300.0}, Eigen::Vector3d(north_m, east_m, down_m));
  s.vel_ned_mps = Eigen::Vector3d(50.0 + north_m, -3.0, 0.5);
  s.q_b_to_n = Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()));
  return s;
}

std::vector<nc::LaneStatus> lanes(double r0, double r1, double r2) {
  return {{true, r0, state(0.0, 0.0, 0.0, 0.10)},
          {true, r1, state(2.5, -1.5, 0.4, 0.13)},
          {true, r2, state(-1.0, 0.7, -0.2, 0.08)}};
}

}  // namespace

TEST(LaneSelector, StartsOnTheBestLaneWithoutCountingAReset) {
  nc::LaneSelector sel;
  const auto& s = sel.update(lanes(0.4, 0.2, 0.9));
  EXPECT_EQ(s.lane, 1);
  EXPECT_EQ(s.reason, nc::LaneSwitchReason::kFirst);
  EXPECT_FALSE(s.switched);
  EXPECT_EQ(s.reset_count, 0u);
}

TEST(LaneSelector, SwitchesOnlyOnAClearAndLastingAdvantage) {
  // Given lane 0 selected, when lane 2 fits better but not by the switch ratio, or by it for
  // one epoch fewer than confirm_epochs, then nothing switches; when it keeps the advantage for
  // confirm_epochs epochs, the selector switches once and counts it once.
  nc::LaneSelectorConfig c;
  c.switch_ratio = 0.5;
  c.confirm_epochs = 3;
  nc::LaneSelector sel(c);
  ASSERT_EQ(sel.update(lanes(0.2, 0.9, 0.9)).lane, 0);
  for (int k = 0; k < 10; ++k) EXPECT_EQ(sel.update(lanes(0.4, 0.9, 0.3)).lane, 0);  // 0.75x
  for (int k = 0; k < 2; ++k) EXPECT_FALSE(sel.update(lanes(0.4, 0.9, 0.1)).switched);
  EXPECT_FALSE(sel.update(lanes(0.4, 0.9, 0.9)).switched);  // the advantage is lost: start again
  for (int k = 0; k < 2; ++k) EXPECT_FALSE(sel.update(lanes(0.4, 0.9, 0.1)).switched);
  const auto& s = sel.update(lanes(0.4, 0.9, 0.1));
  EXPECT_TRUE(s.switched);
  EXPECT_EQ(s.lane, 2);
  EXPECT_EQ(s.previous_lane, 0);
  EXPECT_EQ(s.reason, nc::LaneSwitchReason::kBetterFit);
  EXPECT_EQ(s.reset_count, 1u);
  EXPECT_FALSE(sel.update(lanes(0.4, 0.9, 0.1)).switched);
  EXPECT_EQ(sel.last().reset_count, 1u);
  EXPECT_EQ(sel.last().delta.position_ned_m, Eigen::Vector3d::Zero());
}

TEST(LaneSelector, LeavesAnExcludedLaneAtOnceAndReportsTheJump) {
  // Given lane 1 selected, when its IMU is excluded, then the selector switches at that epoch
  // to the best available lane, and the deltas carry the old solution onto the new one: position
  // to 1 mm, velocity and attitude to rounding.
  nc::LaneSelector sel;
  ASSERT_EQ(sel.update(lanes(0.5, 0.1, 0.3)).lane, 1);
  auto l = lanes(0.5, 0.1, 0.3);
  l[1].available = false;
  const auto& s = sel.update(l);
  ASSERT_TRUE(s.switched);
  EXPECT_EQ(s.lane, 2);
  EXPECT_EQ(s.reason, nc::LaneSwitchReason::kUnavailable);
  EXPECT_EQ(s.reset_count, 1u);
  const nc::NavState& from = l[1].solution;
  const nc::NavState& to = l[2].solution;
  const Eigen::Vector3d residual_m = nc::earth::differenceNed(
      nc::earth::offsetNed(from.position, s.delta.position_ned_m), to.position);
  EXPECT_LT(residual_m.norm(), 1e-3);
  EXPECT_GT(s.delta.position_ned_m.norm(), 3.0);
  EXPECT_LT((from.vel_ned_mps + s.delta.velocity_ned_mps - to.vel_ned_mps).norm(), 1e-12);
  const double angle = s.delta.attitude_ned_rad.norm();
  const Eigen::Quaterniond turned =
      Eigen::Quaterniond(Eigen::AngleAxisd(angle, s.delta.attitude_ned_rad / angle)) *
      from.q_b_to_n;
  EXPECT_LT(turned.angularDistance(to.q_b_to_n), 1e-12);
  EXPECT_NEAR(angle, 0.05, 1e-9);  // the two lanes' yaws differ by 0.05 rad
}

TEST(LaneSelector, WithNoLaneAvailableSelectsNoneAndTakesTheFirstThatReturns) {
  nc::LaneSelector sel;
  auto l = lanes(0.1, 0.2, 0.3);
  for (auto& x : l) x.available = false;
  EXPECT_EQ(sel.update(l).lane, -1);
  l[2].available = true;
  const auto& s = sel.update(l);
  EXPECT_EQ(s.lane, 2);
  EXPECT_FALSE(s.switched);
  EXPECT_EQ(s.reset_count, 0u);
}

TEST(LaneSelector, ALaneWithoutAFitYetIsNeverABetterOne) {
  // Given lane 0 selected, when lane 1 re-initialises (its window starts over: ratio 0), then it
  // is not "a clearly better fit", however long; when the selected lane becomes unavailable, a
  // lane with a fit is taken before one without. (Measured before: a faulty lane re-initialised
  // every ~25 s and was switched to each time, 12 switches in 150 s.)
  nc::LaneSelectorConfig c;
  c.confirm_epochs = 3;
  nc::LaneSelector sel(c);
  ASSERT_EQ(sel.update(lanes(0.9, 1.2, 1.5)).lane, 0);
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(sel.update(lanes(0.9, 0.0, 1.5)).switched);
  auto l = lanes(0.9, 0.0, 1.5);
  l[0].available = false;
  const auto& s = sel.update(l);
  EXPECT_EQ(s.lane, 2);
  EXPECT_EQ(s.reason, nc::LaneSwitchReason::kUnavailable);
  l[2].available = false;  // nothing with a fit left: the one without is better than none
  EXPECT_EQ(sel.update(l).lane, 1);
}

TEST(LaneSelector, APreferredLaneIsTakenFirstAndWhenTheSelectedOneIsLeft) {
  nc::LaneSelectorConfig config;
  config.preferred = 2;
  config.confirm_epochs = 3;
  nc::LaneSelector sel(config);
  EXPECT_EQ(sel.update(lanes(0.4, 0.2, 0.9)).lane, 2) << "preferred, though not the best fit";
  // Hysteresis as for any lane: a clearly better one for 3 epochs in a row is taken.
  for (int k = 0; k < 3; ++k) sel.update(lanes(0.4, 0.2, 0.9));
  EXPECT_EQ(sel.last().lane, 1);
  EXPECT_EQ(sel.last().reason, nc::LaneSwitchReason::kBetterFit);
  auto l = lanes(0.4, 0.2, 0.9);
  l[1].available = false;
  EXPECT_EQ(sel.update(l).lane, 2) << "back to the preferred lane, not to lane 0 (0.4)";
  l[2].available = false;
  EXPECT_EQ(sel.update(l).lane, 0) << "the preferred lane unavailable: the best available";
}
