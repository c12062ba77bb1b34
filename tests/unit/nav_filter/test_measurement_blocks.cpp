// Epochs, fixes and attitudes in blocks (the simulator's fast pacing): the batcher packs one
// sensor's measurements in order up to the IDL bound, and the filter pipeline given the blocks
// produces the same solutions, bit for bit, as given every measurement alone, counting each
// element under its own topic and the blocks under theirs.
#include <gtest/gtest.h>

#include <vector>

#include "navbus/bus/config.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/bus/streams.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/filter_pipeline.hpp"
#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sensor_sim/imu_block_batcher.hpp"
#include "navbus/sensor_sim/measurement_block_batcher.hpp"
#include "navbus/sim/scenario_source.hpp"

using namespace navbus;

namespace {

/// A vehicle at rest with a fix every 0.2 s and an attitude every 0.05 s, IMU at 100 Hz.
struct Frames {
  std::vector<ImuIncrement> increments;
  std::vector<GnssFix> fixes;  ///< at the increments' times
  std::vector<StarTrackerAttitude> attitudes;
  std::vector<std::size_t> fix_frame, attitude_frame;  ///< the frame (increment) of each
};
Frames frames(int n) {
  sim::ScenarioConfig c;
  c.vehicle.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  c.start_time_ns = 1'400'000'000'000'000'000;
  c.raw_samples_per_increment = 1;
  c.gnss_every_n_increments = 20;
  c.star_tracker_every_n_increments = 5;
  sim::ScenarioSource src(c);
  Frames f;
  for (int k = 1; k <= n; ++k) {
    const sim::SensorFrame frame = src.next();
    f.increments.push_back(bus::toIdl(frame.increment, 1, static_cast<std::uint64_t>(k)));
    if (frame.has_gnss) {
      f.fixes.push_back(sensor_sim::toIdl(frame.fix, 1, f.fixes.size() + 1));
      f.fix_frame.push_back(static_cast<std::size_t>(k - 1));
    }
    if (frame.has_star_tracker) {
      f.attitudes.push_back(sensor_sim::toIdl(frame.star_tracker, 1, f.attitudes.size() + 1));
      f.attitude_frame.push_back(static_cast<std::size_t>(k - 1));
    }
  }
  return f;
}

bool sameBits(const NavigationSolution& a, const NavigationSolution& b) {
  return a.time_gps_ns() == b.time_gps_ns() && a.latitude_rad() == b.latitude_rad() &&
         a.longitude_rad() == b.longitude_rad() && a.height_m() == b.height_m() &&
         a.vel_ned_mps() == b.vel_ned_mps() && a.q_b_to_n() == b.q_b_to_n() &&
         a.pos_sigma_ned_m() == b.pos_sigma_ned_m();
}

}  // namespace

TEST(MeasurementBlockBatcher, PacksOneSensorsElementsInOrderUpToTheBound) {
  const Frames f = frames(400);
  ASSERT_EQ(f.attitudes.size(), 80u);
  sensor_sim::MeasurementBlockBatcher<StarTrackerAttitudeBlock> batcher;
  EXPECT_TRUE(batcher.empty());
  std::vector<StarTrackerAttitudeBlock> blocks;
  for (const StarTrackerAttitude& a : f.attitudes) {
    if (!batcher.add(a)) {
      blocks.push_back(batcher.take());
      ASSERT_TRUE(batcher.add(a)) << "room again after the take";
    }
  }
  blocks.push_back(batcher.take());
  EXPECT_TRUE(batcher.empty());
  constexpr std::size_t kBound = bus::SensorBlock<StarTrackerAttitudeBlock>::kMaxElements;
  ASSERT_EQ(blocks.size(), (80 + kBound - 1) / kBound);
  std::size_t next = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    EXPECT_EQ(blocks[b].seq(), b + 1);
    EXPECT_EQ(blocks[b].tracker_id(), 1u);
    EXPECT_LE(blocks[b].attitudes().size(), kBound);
    for (const StarTrackerAttitude& a : blocks[b].attitudes()) EXPECT_EQ(a, f.attitudes[next++]);
  }
  EXPECT_EQ(next, f.attitudes.size());
}

TEST(FilterPipelineBlocks, MeasurementBlocksGiveTheSameSolutionsAsSingleSamples) {
  const auto cfg = nav_filter::parseFilterConfig(
      YAML::Load("initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}\n"
                 "mode: loosely_coupled\n"
                 "star_tracker_updates: true\n"
                 "inputs: {imu: {id: 1, period_s: 0.01}, gnss_fix: {id: 1, period_s: 0.2},\n"
                 "         star_tracker: {id: 1, period_s: 0.05}}\n"));
  const Frames f = frames(600);
  bus::HealthCounters single_health("single"), block_health("blocks");
  std::vector<NavigationSolution> single, blocked;
  nav_filter::FilterPipeline one(
      cfg, single_health, {[&](const NavigationSolution& s) { single.push_back(s); }, nullptr});
  nav_filter::FilterPipeline many(
      cfg, block_health, {[&](const NavigationSolution& s) { blocked.push_back(s); }, nullptr});
  // As the simulator writes them: an increment block of 0.5 s, then the fixes' and the
  // attitudes' blocks of the same frames (2-3 fixes, 10 attitudes each).
  sensor_sim::ImuBlockBatcher increments(50);
  sensor_sim::MeasurementBlockBatcher<GnssFixBlock> fixes;
  sensor_sim::MeasurementBlockBatcher<StarTrackerAttitudeBlock> attitudes;
  std::size_t next_fix = 0, next_attitude = 0;
  std::int64_t now = 0;
  for (std::size_t k = 0; k < f.increments.size(); ++k) {
    one.onImu(f.increments[k]);
    increments.addIncrement(f.increments[k]);
    for (; next_fix < f.fixes.size() && f.fix_frame[next_fix] == k; ++next_fix) {
      one.onGnssFix(f.fixes[next_fix]);
      ASSERT_TRUE(fixes.add(f.fixes[next_fix]));
    }
    for (; next_attitude < f.attitudes.size() && f.attitude_frame[next_attitude] == k;
         ++next_attitude) {
      one.onStarTracker(f.attitudes[next_attitude]);
      ASSERT_TRUE(attitudes.add(f.attitudes[next_attitude]));
    }
    one.pump(now += 10'000'000);
    if (increments.full()) {
      many.onImuBlock(increments.takeIncrements());
      if (!fixes.empty()) many.onGnssFixBlock(fixes.take());
      if (!attitudes.empty()) many.onStarTrackerBlock(attitudes.take());
      many.pump(now);
    }
  }
  // A block whose element names another receiver is refused whole, naming the element; an
  // empty one is refused too.
  GnssFixBlock foreign;
  foreign.receiver_id(1);
  foreign.seq(100);
  foreign.fixes().push_back(f.fixes[0]);
  foreign.fixes().back().receiver_id(2);
  many.onGnssFixBlock(foreign);
  StarTrackerAttitudeBlock empty;
  empty.tracker_id(1);
  empty.seq(100);
  many.onStarTrackerBlock(empty);
  one.flush(now);
  many.flush(now);

  ASSERT_EQ(f.fixes.size(), 30u);
  ASSERT_EQ(f.attitudes.size(), 120u);
  ASSERT_EQ(single.size(), 60u);
  ASSERT_EQ(blocked.size(), single.size());
  for (std::size_t k = 0; k < single.size(); ++k) EXPECT_TRUE(sameBits(single[k], blocked[k])) << k;
  const bus::StreamCounters& fix_single = *single_health.find(bus::topic::kGnssFix);
  const bus::StreamCounters& fix_elements = *block_health.find(bus::topic::kGnssFix);
  EXPECT_EQ(fix_elements.received, 30u);
  EXPECT_EQ(fix_elements.accepted, fix_single.accepted);
  EXPECT_EQ(fix_elements.accepted, 30u);
  EXPECT_EQ(block_health.find(bus::topic::kStarTracker)->received, 120u);
  EXPECT_EQ(block_health.find(bus::topic::kStarTracker)->accepted,
            single_health.find(bus::topic::kStarTracker)->accepted);
  const bus::StreamCounters& fix_blocks = *block_health.find(bus::topic::kGnssFixBlock);
  EXPECT_EQ(fix_blocks.accepted, 12u);
  EXPECT_EQ(fix_blocks.rejected.at(REJECT_INCONSISTENT), 1u);
  EXPECT_EQ(fix_blocks.sequence_gaps, 0u);
  const bus::StreamCounters& attitude_blocks = *block_health.find(bus::topic::kStarTrackerBlock);
  EXPECT_EQ(attitude_blocks.accepted, 12u);
  EXPECT_EQ(attitude_blocks.rejected.at(REJECT_OUT_OF_RANGE), 1u);
}

TEST(MeasurementBlockValidation, NamesTheElementThatNamesAnotherSensor) {
  GnssObservationEpochBlock block;
  block.receiver_id(3);
  block.epochs().resize(2);
  block.epochs()[0].receiver_id(3);
  block.epochs()[1].receiver_id(4);
  const auto r = bus::validate(block, bus::ValidationLimits{});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->reason, REJECT_INCONSISTENT);
  EXPECT_EQ(r->field, "epochs[1].receiver_id");
  EXPECT_EQ(r->value, 4.0);
  block.epochs()[1].receiver_id(3);
  EXPECT_FALSE(bus::validate(block, bus::ValidationLimits{}));
  block.epochs().clear();
  ASSERT_TRUE(bus::validate(block, bus::ValidationLimits{}));
  EXPECT_EQ(bus::validate(block, bus::ValidationLimits{})->field, "epochs.size");
}
