// The samples the simulator participant publishes for a scenario, one vector per IMU cycle (as
// emitFrame orders them, raw blocks left out), and their delivery to a filter's DDS-free path
// (FilterPipeline or LaneSet): shared by the benchmarks of the filter participant.
#pragma once

#include <cstdint>
#include <type_traits>
#include <variant>
#include <vector>

#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/scenario_source.hpp"

namespace navbus::bench {

using FilterSample = std::variant<ImuIncrement, GnssObservationEpoch, GnssFix, StarTrackerAttitude>;

inline std::vector<std::vector<FilterSample>> filterSamples(const sensor_sim::SimConfig& sim,
                                                            int cycles) {
  sim::ScenarioSource src(sim.scenario);
  sensor_sim::SimConfig emitted = sim;
  emitted.publish_raw = false;
  sensor_sim::FrameSequence seq;
  std::vector<std::vector<FilterSample>> out(static_cast<std::size_t>(cycles));
  for (auto& cycle : out) {
    sensor_sim::emitFrame(src.next(), emitted, seq, [&cycle](const auto& s) {
      using T = std::decay_t<decltype(s)>;
      if constexpr (std::is_constructible_v<FilterSample, T>) cycle.emplace_back(s);
      return true;
    });
  }
  return out;
}

/// Hands one sample to `filter`; returns its data time if it is an increment, else -1.
template <class Filter>
std::int64_t feed(Filter& filter, const FilterSample& sample) {
  return std::visit(
      [&](const auto& m) -> std::int64_t {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, ImuIncrement>) {
          filter.onImu(m);
          return static_cast<std::int64_t>(m.time_gps_ns());
        } else if constexpr (std::is_same_v<T, GnssObservationEpoch>) {
          filter.onGnssObservations(m);
        } else if constexpr (std::is_same_v<T, GnssFix>) {
          filter.onGnssFix(m);
        } else {
          filter.onStarTracker(m);
        }
        return -1;
      },
      sample);
}

}  // namespace navbus::bench
