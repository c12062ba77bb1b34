// Runs of the filter pipeline on the simulator's default scenario (aircraft at rest, GNSS at
// 1 Hz), fed sample by sample as the participant is, for the pipeline tests that compare two
// runs bit for bit.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "navbus/bus/config.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/filter_pipeline.hpp"
#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/scenario_source.hpp"

namespace navbus::test {

using Sample = std::variant<ImuIncrement, GnssObservationEpoch, GnssFix>;
using Frame = std::vector<Sample>;

/// `n` frames of the default scenario (aircraft at rest, GNSS at 1 Hz), as the simulator
/// participant emits them.
inline std::vector<Frame> frames(int n) {
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

inline nav_filter::FilterConfig tightlyCoupled(double history_s, const std::string& more = "") {
  return nav_filter::parseFilterConfig(YAML::Load(
      "initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}\n"
      "mode: tightly_coupled\n"
      "recovery: {history_s: " +
      std::to_string(history_s) +
      "}\n"
      "inputs: {imu: {id: 1, period_s: 0.01}, gnss_observations: {id: 1, period_s: 1.0}}\n" +
      more));
}

struct FilterRun {
  std::vector<NavigationSolution> solutions;
  std::vector<FilterDiagnostics> diagnostics;
  bus::HealthCounters health{"test"};
  std::unique_ptr<nav_filter::FilterPipeline> pipeline;
  /// Called with each diagnostics epoch as it is published (a fault manager in the loop).
  std::function<void(const FilterDiagnostics&)> on_diagnostics;
  /// Called before each frame is fed, with its index (what arrives from elsewhere meanwhile).
  std::function<void(std::size_t)> before_frame;

  explicit FilterRun(const nav_filter::FilterConfig& config) {
    pipeline = std::make_unique<nav_filter::FilterPipeline>(
        config, health,
        nav_filter::FilterPipeline::Sinks{
            [this](const NavigationSolution& s) { solutions.push_back(s); },
            [this](const FilterDiagnostics& d) {
              diagnostics.push_back(d);
              if (on_diagnostics) on_diagnostics(d);
            }});
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
      if (before_frame) before_frame(k);
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
    if (before_frame) before_frame(std::numeric_limits<std::size_t>::max());  // the rest arrives
    pipeline->flush(now);
  }
};

inline bool sameBits(const NavigationSolution& a, const NavigationSolution& b) {
  return a.seq() == b.seq() && a.time_gps_ns() == b.time_gps_ns() &&
         a.latitude_rad() == b.latitude_rad() && a.longitude_rad() == b.longitude_rad() &&
         a.height_m() == b.height_m() && a.vel_ned_mps() == b.vel_ned_mps() &&
         a.q_b_to_n() == b.q_b_to_n() && a.pos_sigma_ned_m() == b.pos_sigma_ned_m();
}

/// Data time of a frame (its increment's).
inline std::uint64_t timeOf(const Frame& frame) {
  return std::get<ImuIncrement>(frame.front()).time_gps_ns();
}

inline void expectSameEngine(const core::NavigationEngine& a, const core::NavigationEngine& b) {
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

}  // namespace navbus::test
