// The increments of several IMU units aligned by time (imu_alignment.hpp): a time goes out when
// every unit gave it, or, incomplete, when a unit missing there has gone past it, has ended, or
// a silent unit holds more than `depth` times; late and repeated increments are told.
#include <gtest/gtest.h>

#include "navbus/bus/imu_alignment.hpp"

using navbus::bus::ImuUnitAligner;

namespace {

navbus::core::ImuIncrement at(std::int64_t time_ns, double x = 0.0) {
  navbus::core::ImuIncrement inc;
  inc.time_ns = time_ns;
  inc.interval_s = 0.01;
  inc.delta_angle_b_rad.x() = x;
  return inc;
}

}  // namespace

TEST(ImuUnitAligner, ReleasesEachTimeWhenEveryUnitGaveItInTimeOrder) {
  ImuUnitAligner a(3, 100);
  EXPECT_EQ(a.add(0, at(10, 1.0)), ImuUnitAligner::Added::kTaken);
  EXPECT_EQ(a.add(0, at(20)), ImuUnitAligner::Added::kTaken);
  EXPECT_EQ(a.add(0, at(20)), ImuUnitAligner::Added::kRepeated);
  EXPECT_FALSE(a.next().has_value()) << "10 waits for units 1 and 2";
  a.add(2, at(10));
  EXPECT_FALSE(a.next().has_value()) << "10 waits for unit 1, which has not gone past it";
  a.add(1, at(10, 3.0));
  a.add(1, at(20));
  auto s = a.next();
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->time_ns, 10);
  EXPECT_TRUE(a.complete(*s));
  EXPECT_EQ(s->units[1].delta_angle_b_rad.x(), 3.0);
  EXPECT_EQ(a.releasedNs(), 10);
  EXPECT_EQ(a.add(2, at(10)), ImuUnitAligner::Added::kLate);
  EXPECT_FALSE(a.next(15).has_value()) << "not beyond up_to";
}

TEST(ImuUnitAligner, ATimeAMissingUnitPassedOrThatAnEndedUnitOwesGoesOutIncomplete) {
  ImuUnitAligner a(2, 100);
  a.add(0, at(10));
  a.add(0, at(20));
  a.add(1, at(20));  // unit 1 went past 10 (its reader delivers in order): 10 is lost to it
  auto s = a.next();
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->time_ns, 10);
  EXPECT_EQ(s->present, 0b01u);
  EXPECT_FALSE(a.complete(*s));
  EXPECT_TRUE(a.complete(*a.next()));
  a.add(0, at(30));
  EXPECT_FALSE(a.next().has_value());
  a.endUnit(1);
  s = a.next();
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->present, 0b01u);
}

TEST(ImuUnitAligner, ASilentUnitHoldsAtMostDepthTimes) {
  ImuUnitAligner a(2, 3);
  for (int k = 1; k <= 3; ++k) a.add(0, at(10 * k));
  EXPECT_FALSE(a.next().has_value());
  a.add(0, at(40));
  auto s = a.next();
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->time_ns, 10);
  EXPECT_FALSE(a.next().has_value());
  EXPECT_EQ(a.flushNext()->time_ns, 20);
  a.clear();
  EXPECT_EQ(a.waiting(), 0u);
  EXPECT_EQ(a.add(0, at(5)), ImuUnitAligner::Added::kTaken) << "a new run";
}
