// Samples that come after their place in the order was passed (a stalled filter process, a
// stream set aside by the bounded wait) are merged by rewinding: the engine is restored from
// the input history to before the sample, and what followed is merged again with it. The
// result is the in-time result bit for bit; beyond the history a late sample is refused and
// counted.
#include <gtest/gtest.h>

#include "navbus/bus/topics.hpp"
#include "pipeline_runs.hpp"

using namespace navbus;

using namespace navbus::test;

namespace {

/// Samples refused as late (after their place, beyond the history).
std::uint64_t lateOf(const bus::StreamCounters& c) {
  const auto it = c.rejected.find(REJECT_LATE);
  return it == c.rejected.end() ? 0 : it->second;
}

constexpr std::size_t kFrames = 1500;                   // 15 s of data
constexpr std::size_t kHoldFrom = 700, kHoldTo = 1000;  // 3 s of increments late

}  // namespace

TEST(LateSamples, MergedByRewindingGiveTheInTimeResultBitForBit) {
  const std::vector<Frame> all = frames(kFrames);
  const auto config = tightlyCoupled(40.0);
  FilterRun in_time(config), late(config);
  in_time.play(all);
  late.play(all, kHoldFrom, kHoldTo);

  const bus::StreamCounters& imu = *late.health.find(bus::topic::kImuIncrement);
  EXPECT_EQ(lateOf(imu), 0u) << late.pipeline->summary();
  EXPECT_EQ(imu.accepted, kFrames);
  EXPECT_NE(late.pipeline->summary().find("late samples merged by rewinding 1 (rewinds 1)"),
            std::string::npos)
      << late.pipeline->summary();
  EXPECT_EQ(late.pipeline->summary().find("sequencer timeouts 0,"), std::string::npos)
      << "the bounded wait did pass the IMU by: " << late.pipeline->summary();

  expectSameEngine(in_time.pipeline->engine(), late.pipeline->engine());
  // Every solution time once, and each the in-time one (nothing was published while the
  // increments were missing).
  ASSERT_EQ(late.solutions.size(), in_time.solutions.size());
  for (std::size_t k = 0; k < in_time.solutions.size(); ++k)
    EXPECT_TRUE(sameBits(in_time.solutions[k], late.solutions[k])) << k;
  // Diagnostics: one per epoch. Those published while the IMU was set aside went out before
  // the rewind could correct them (stamped with the engine's stale time); every later one is
  // the in-time one.
  ASSERT_EQ(late.diagnostics.size(), in_time.diagnostics.size());
  const std::uint64_t resumed_ns = timeOf(all[kHoldTo]);
  for (std::size_t k = 0; k < in_time.diagnostics.size(); ++k) {
    if (in_time.diagnostics[k].time_gps_ns() < resumed_ns) continue;
    EXPECT_EQ(late.diagnostics[k].time_gps_ns(), in_time.diagnostics[k].time_gps_ns()) << k;
    EXPECT_EQ(late.diagnostics[k].innovation(), in_time.diagnostics[k].innovation()) << k;
  }
}

TEST(LateSamples, LateMeasurementsAreMergedToo) {
  const std::vector<Frame> all = frames(kFrames);
  const auto config = tightlyCoupled(40.0);
  FilterRun in_time(config), late(config);
  in_time.play(all);
  late.play<GnssObservationEpoch>(all, kHoldFrom, kHoldTo);
  const bus::StreamCounters& gnss = *late.health.find(bus::topic::kGnssObservations);
  EXPECT_EQ(lateOf(gnss), 0u) << late.pipeline->summary();
  expectSameEngine(in_time.pipeline->engine(), late.pipeline->engine());
  // The solutions published while the receiver was set aside lacked its epochs (published
  // once, they stay so); from the rewind on, each is the in-time one.
  ASSERT_EQ(late.solutions.size(), in_time.solutions.size());
  const std::uint64_t resumed_ns = timeOf(all[kHoldTo]);
  for (std::size_t k = 0; k < in_time.solutions.size(); ++k) {
    if (in_time.solutions[k].time_gps_ns() < resumed_ns) continue;
    EXPECT_TRUE(sameBits(in_time.solutions[k], late.solutions[k])) << k;
  }
  ASSERT_EQ(late.diagnostics.size(), in_time.diagnostics.size());
  for (std::size_t k = 0; k < in_time.diagnostics.size(); ++k)
    EXPECT_EQ(late.diagnostics[k].innovation(), in_time.diagnostics[k].innovation()) << k;
}

TEST(LateSamples, BeyondTheHistoryAreRefusedAndCounted) {
  const std::vector<Frame> all = frames(kFrames);
  const auto config = tightlyCoupled(1.0);  // a history shorter than the 3 s held back
  FilterRun in_time(config), late(config);
  in_time.play(all);
  late.play<GnssObservationEpoch>(all, kHoldFrom, kHoldTo);
  const bus::StreamCounters& gnss = *late.health.find(bus::topic::kGnssObservations);
  EXPECT_GT(lateOf(gnss), 0u) << late.pipeline->summary();
  EXPECT_EQ(gnss.accepted + lateOf(gnss), in_time.diagnostics.size()) << "each one counted";
  EXPECT_FALSE(late.pipeline->engine().covariance() == in_time.pipeline->engine().covariance())
      << "the epochs refused are missing from the estimate";
}
