// Samples that come after their place in the order was passed (a stalled filter process, a
// stream set aside by the bounded wait) are merged by rewinding: the engine is restored from
// the input history to before the sample, and what followed is merged again with it. The
// result is the in-time result bit for bit; beyond the history a late sample is refused and
// counted.
#include <gtest/gtest.h>

#include <variant>
#include <vector>

#include "navbus/bus/config.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/filter_pipeline.hpp"
#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/scenario_source.hpp"

using namespace navbus;

namespace {

using Sample = std::variant<ImuIncrement, GnssObservationEpoch, GnssFix>;
using Frame = std::vector<Sample>;

/// `n` frames of the default scenario (aircraft at rest, GNSS at 1 Hz), as the simulator
/// participant emits them.
std::vector<Frame> frames(int n) {
  sensor_sim::SimConfig sim;
  sim.scenario.start_time_ns = 1'400'000'000'000'000'000;
  sim.publish_raw = false;
  sim.publish_star_tracker = false;
  sim::ScenarioSource source(sim.scenario);
  sensor_sim::FrameSequence seq;
  std::vector<Frame> out(static_cast<std::size_t>(n));
  for (Frame& frame : out) {
    sensor_sim::emitFrame(source.next(), sim, seq, [&frame](const auto& s) {
      using T = std::decay_t<decltype(s)>;
      if constexpr (std::is_constructible_v<Sample, T>) frame.emplace_back(s);
      return true;
    });
  }
  return out;
}

nav_filter::FilterConfig tightlyCoupled(double history_s) {
  return nav_filter::parseFilterConfig(YAML::Load(
      "initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}\n"
      "mode: tightly_coupled\n"
      "recovery: {history_s: " +
      std::to_string(history_s) +
      "}\n"
      "inputs: {imu: {id: 1, period_s: 0.01}, gnss_observations: {id: 1, period_s: 1.0}}\n"));
}

struct FilterRun {
  std::vector<NavigationSolution> solutions;
  std::vector<FilterDiagnostics> diagnostics;
  bus::HealthCounters health{"test"};
  std::unique_ptr<nav_filter::FilterPipeline> pipeline;

  explicit FilterRun(const nav_filter::FilterConfig& config) {
    pipeline = std::make_unique<nav_filter::FilterPipeline>(
        config, health,
        nav_filter::FilterPipeline::Sinks{
            [this](const NavigationSolution& s) { solutions.push_back(s); },
            [this](const FilterDiagnostics& d) { diagnostics.push_back(d); }});
  }

  void feed(const Sample& s) {
    std::visit(
        [this](const auto& m) {
          using T = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<T, ImuIncrement>) pipeline->onImu(m);
          if constexpr (std::is_same_v<T, GnssObservationEpoch>) pipeline->onGnssObservations(m);
          if constexpr (std::is_same_v<T, GnssFix>) pipeline->onGnssFix(m);
        },
        s);
  }

  /// Feeds every frame, pumping 10 ms of wall time after each. The samples of type `Held` of
  /// frames [hold_from, hold_to) are held back (the filter stalled on that stream) and
  /// delivered, late, just before frame hold_to; meanwhile the bounded wait sets the stream
  /// aside and releases the others past it.
  template <class Held = ImuIncrement>
  void play(const std::vector<Frame>& all, std::size_t hold_from = 0, std::size_t hold_to = 0) {
    std::int64_t now = 0;
    std::vector<Sample> held;
    for (std::size_t k = 0; k < all.size(); ++k) {
      if (k == hold_to) {
        for (const Sample& s : held) feed(s);
        held.clear();
      }
      for (const Sample& s : all[k]) {
        if (k >= hold_from && k < hold_to && std::holds_alternative<Held>(s))
          held.push_back(s);
        else
          feed(s);
      }
      pipeline->pump(now += 10'000'000);
    }
    pipeline->flush(now);
  }
};

bool sameBits(const NavigationSolution& a, const NavigationSolution& b) {
  return a.seq() == b.seq() && a.time_gps_ns() == b.time_gps_ns() &&
         a.latitude_rad() == b.latitude_rad() && a.longitude_rad() == b.longitude_rad() &&
         a.height_m() == b.height_m() && a.vel_ned_mps() == b.vel_ned_mps() &&
         a.q_b_to_n() == b.q_b_to_n() && a.pos_sigma_ned_m() == b.pos_sigma_ned_m();
}

/// Samples refused as late (after their place, beyond the history).
std::uint64_t lateOf(const bus::StreamCounters& c) {
  const auto it = c.rejected.find(REJECT_LATE);
  return it == c.rejected.end() ? 0 : it->second;
}

/// Data time of a frame (its increment's).
std::uint64_t timeOf(const Frame& frame) {
  return std::get<ImuIncrement>(frame.front()).time_gps_ns();
}

void expectSameEngine(const core::NavigationEngine& a, const core::NavigationEngine& b) {
  EXPECT_EQ(a.state().time_ns, b.state().time_ns);
  EXPECT_TRUE(a.state().position.latitude_rad == b.state().position.latitude_rad &&
              a.state().position.longitude_rad == b.state().position.longitude_rad &&
              a.state().position.height_m == b.state().position.height_m);
  EXPECT_TRUE(a.state().vel_ned_mps == b.state().vel_ned_mps);
  EXPECT_TRUE(a.state().q_b_to_n.coeffs() == b.state().q_b_to_n.coeffs());
  EXPECT_TRUE(a.accelBias() == b.accelBias());
  EXPECT_TRUE(a.gyroBias() == b.gyroBias());
  EXPECT_TRUE(a.covariance() == b.covariance()) << "the full covariance, bit for bit";
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
