// The mechanization's velocity history (core/ins/velocity_history.hpp): what brings a lagging
// GNSS velocity to the state's time.
#include <gtest/gtest.h>

#include "navbus/core/ins/velocity_history.hpp"

namespace navbus::core {
namespace {

constexpr std::int64_t kStepNs = 10'000'000;  // 100 Hz

TEST(VelocityHistory, AConstantAccelerationGivesItsChangeOverAnyInterval) {
  // Given increments of a constant acceleration, when asked for the change since a time
  // between two increments, then it is a times the interval, exactly (linear within one).
  const Eigen::Vector3d a_ned(1.5, -0.5, 0.2);
  VelocityHistory h;
  for (int k = 1; k <= 200; ++k) h.add(k * kStepNs, a_ned * 0.01);
  Eigen::Vector3d dv;
  const std::int64_t latest = 200 * kStepNs;
  ASSERT_TRUE(h.changeSince(latest - 132'000'000, dv));
  EXPECT_LT((dv - a_ned * 0.132).norm(), 1e-12);
  ASSERT_TRUE(h.changeSince(latest, dv));
  EXPECT_EQ(dv, Eigen::Vector3d::Zero());
  ASSERT_TRUE(h.changeSince(latest + kStepNs, dv)) << "later than the state: nothing to add";
  EXPECT_EQ(dv, Eigen::Vector3d::Zero());
}

TEST(VelocityHistory, ItDoesNotReachBeyondItsLengthNorBeforeItsFirstIncrement) {
  VelocityHistory h;
  Eigen::Vector3d dv;
  h.add(kStepNs, Eigen::Vector3d::Ones());
  EXPECT_FALSE(h.changeSince(0, dv)) << "one increment is no interval";
  for (int k = 2; k <= 3 * VelocityHistory::kLength; ++k)
    h.add(k * kStepNs, Eigen::Vector3d::Ones());
  const std::int64_t latest = 3 * VelocityHistory::kLength * kStepNs;
  const std::int64_t oldest = latest - (VelocityHistory::kLength - 1) * kStepNs;
  ASSERT_TRUE(h.changeSince(oldest, dv));
  EXPECT_NEAR(dv.x(), VelocityHistory::kLength - 1, 1e-9);
  EXPECT_FALSE(h.changeSince(oldest - 1, dv));
  h.clear();
  EXPECT_FALSE(h.changeSince(latest, dv)) << "cleared at a start";
}

}  // namespace
}  // namespace navbus::core
