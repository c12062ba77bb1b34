// Increments and raw samples in blocks (the simulator's fast pacing): the batcher packs the same
// data in order, and the filter pipeline given the blocks produces the same solutions, bit for
// bit, as given every increment alone, counting each increment under the increment topic.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "navbus/bus/config.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/filter_pipeline.hpp"
#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sensor_sim/imu_block_batcher.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/scenario_source.hpp"

using namespace navbus;

namespace {

sim::ScenarioConfig sourceConfig() {
  sim::ScenarioConfig c;
  c.vehicle.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  c.start_time_ns = 1'400'000'000'000'000'000;
  c.raw_samples_per_increment = 4;
  return c;
}

/// `n` consecutive frames' increments and raw blocks, numbered from 1.
struct Frames {
  std::vector<ImuIncrement> increments;
  std::vector<ImuRawBlock> raw;
};
Frames frames(int n) {
  sim::ScenarioSource src(sourceConfig());
  Frames f;
  for (int k = 1; k <= n; ++k) {
    const sim::SensorFrame frame = src.next();
    f.increments.push_back(bus::toIdl(frame.increment, 1, static_cast<std::uint64_t>(k)));
    f.raw.push_back(sensor_sim::toIdl(frame.raw, 1, static_cast<std::uint64_t>(k)));
  }
  return f;
}

bool sameBits(const NavigationSolution& a, const NavigationSolution& b) {
  return a.time_gps_ns() == b.time_gps_ns() && a.latitude_rad() == b.latitude_rad() &&
         a.longitude_rad() == b.longitude_rad() && a.height_m() == b.height_m() &&
         a.vel_ned_mps() == b.vel_ned_mps() && a.q_b_to_n() == b.q_b_to_n();
}

}  // namespace

TEST(ImuBlockBatcher, PacksConsecutiveIncrementsAndRawSamplesInOrder) {
  const Frames f = frames(45);
  sensor_sim::ImuBlockBatcher batcher(20);
  std::vector<ImuIncrementBlock> blocks;
  std::vector<ImuRawBlock> raw;
  for (std::size_t k = 0; k < f.increments.size(); ++k) {
    batcher.addIncrement(f.increments[k]);
    const bool full = batcher.full();
    ASSERT_TRUE(batcher.addRaw(f.raw[k]));
    EXPECT_EQ(full, (k + 1) % 20 == 0);
    if (full) {
      blocks.push_back(batcher.takeIncrements());
      raw.push_back(batcher.takeRaw());
    }
  }
  blocks.push_back(batcher.takeIncrements());  // the end of the data: a partial block
  raw.push_back(batcher.takeRaw());
  EXPECT_FALSE(batcher.hasIncrements() || batcher.hasRaw());

  ASSERT_EQ(blocks.size(), 3u);
  EXPECT_EQ(blocks[0].increments().size(), 20u);
  EXPECT_EQ(blocks[2].increments().size(), 5u);
  std::size_t k = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    EXPECT_EQ(blocks[b].seq(), b + 1);
    EXPECT_EQ(blocks[b].sensor_id(), 1u);
    for (const ImuIncrement& inc : blocks[b].increments()) EXPECT_TRUE(inc == f.increments[k++]);
  }
  EXPECT_EQ(k, 45u);
  // Raw: the same samples, each block continuing the time of the one before.
  std::size_t sample = 0;
  for (std::size_t b = 0; b < raw.size(); ++b) {
    EXPECT_EQ(raw[b].seq(), b + 1);
    EXPECT_EQ(raw[b].sample_period_ns(), f.raw[0].sample_period_ns());
    EXPECT_EQ(raw[b].first_sample_time_gps_ns(),
              f.raw[0].first_sample_time_gps_ns() + sample * f.raw[0].sample_period_ns());
    for (const ImuRawSample& s : raw[b].samples()) {
      const ImuRawBlock& from = f.raw[sample / 4];
      EXPECT_TRUE(s == from.samples()[sample % 4]);
      ++sample;
    }
  }
  EXPECT_EQ(sample, 45u * 4u);
}

TEST(ImuBlockBatcher, RawSamplesThatDoNotContinueTheBlockAreRefused) {
  const Frames f = frames(3);
  sensor_sim::ImuBlockBatcher batcher(20);
  ASSERT_TRUE(batcher.addRaw(f.raw[0]));
  EXPECT_FALSE(batcher.addRaw(f.raw[2]));  // a gap of one frame
  ImuRawBlock other = f.raw[1];
  other.sensor_id(2);
  EXPECT_FALSE(batcher.addRaw(other));
  ImuRawBlock big = f.raw[1];
  big.samples().resize(sensor_sim::ImuBlockBatcher::kMaxRawSamples);
  EXPECT_FALSE(batcher.addRaw(big));  // beyond the IDL bound together
  EXPECT_TRUE(batcher.addRaw(f.raw[1]));
  EXPECT_EQ(batcher.takeRaw().samples().size(), 8u);
  // 2400 Hz: the period rounded to whole nanoseconds, the times exact; consecutive blocks of
  // 24 samples continue one another although 24 rounded periods miss the next time by 8 ns.
  ImuRawBlock a, b;
  a.sensor_id(1);
  a.sample_period_ns(416'667);
  a.first_sample_time_gps_ns(1'000'000'000);
  a.samples().resize(24);
  b = a;
  b.first_sample_time_gps_ns(1'010'000'000);  // 10 ms later: 24 samples of 1/2400 s
  ASSERT_TRUE(batcher.addRaw(a));
  EXPECT_TRUE(batcher.addRaw(b));
  b.first_sample_time_gps_ns(1'020'000'000 + 416'667);  // one sample missing
  EXPECT_FALSE(batcher.addRaw(b));
  EXPECT_THROW(sensor_sim::ImuBlockBatcher(0), std::invalid_argument);
  EXPECT_THROW(sensor_sim::ImuBlockBatcher(bus::kMaxIncrementsPerBlock + 1), std::invalid_argument);
}

TEST(ImuBlockBatcher, BlockLengthFromTheScenario) {
  auto config = [](const std::string& timing) {
    return sensor_sim::parseSimConfig(YAML::Load("timing: {imu_rate_hz: 200, " + timing + "}"));
  };
  EXPECT_EQ(sensor_sim::incrementsPerBlock(config("pacing: fast")), 60u);  // 0.3 s by default
  EXPECT_EQ(sensor_sim::incrementsPerBlock(config("pacing: fast, fast_pacing_block_s: 0.1")), 20u);
  EXPECT_EQ(sensor_sim::incrementsPerBlock(config("pacing: fast, fast_pacing_block_s: 0")), 0u);
  EXPECT_EQ(sensor_sim::incrementsPerBlock(config("pacing: realtime")), 0u);
  try {
    sensor_sim::incrementsPerBlock(config("pacing: fast, fast_pacing_block_s: 1.0"));
    FAIL() << "200 increments per block accepted";
  } catch (const bus::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("timing.fast_pacing_block_s = 1.0"), std::string::npos)
        << e.what();
  }
}

TEST(FilterPipelineBlocks, BlocksGiveTheSameSolutionsAsSingleIncrements) {
  const auto cfg = nav_filter::parseFilterConfig(
      YAML::Load("initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}\n"
                 "inputs: {imu: {id: 1, period_s: 0.01}}\n"));
  const Frames f = frames(400);
  bus::HealthCounters single_health("single"), block_health("blocks");
  std::vector<NavigationSolution> single, blocked;
  nav_filter::FilterPipeline one(
      cfg, single_health, {[&](const NavigationSolution& s) { single.push_back(s); }, nullptr});
  nav_filter::FilterPipeline many(
      cfg, block_health, {[&](const NavigationSolution& s) { blocked.push_back(s); }, nullptr});
  sensor_sim::ImuBlockBatcher batcher(20);
  std::int64_t now = 0;
  for (const ImuIncrement& inc : f.increments) {
    one.onImu(inc);
    one.pump(now += 10'000'000);
    batcher.addIncrement(inc);
    if (batcher.full()) {
      many.onImuBlock(batcher.takeIncrements());
      many.pump(now);
    }
  }
  // A block whose elements name another sensor is refused whole, naming the element.
  ImuIncrementBlock foreign = batcher.takeIncrements();
  ASSERT_TRUE(foreign.increments().empty());
  foreign.sensor_id(1);
  foreign.increments().push_back(f.increments[0]);
  foreign.increments().back().sensor_id(2);
  many.onImuBlock(foreign);
  one.flush(now);
  many.flush(now);

  ASSERT_EQ(single.size(), 40u);
  ASSERT_EQ(blocked.size(), single.size());
  for (std::size_t k = 0; k < single.size(); ++k) EXPECT_TRUE(sameBits(single[k], blocked[k])) << k;
  const bus::StreamCounters& increments = *block_health.find(bus::topic::kImuIncrement);
  EXPECT_EQ(increments.received, 400u);
  EXPECT_EQ(increments.accepted, 400u);
  const bus::StreamCounters& blocks = *block_health.find(bus::topic::kImuIncrementBlock);
  EXPECT_EQ(blocks.accepted, 20u);
  EXPECT_EQ(blocks.rejected.at(REJECT_INCONSISTENT), 1u);
  EXPECT_EQ(blocks.sequence_gaps, 0u);
}
