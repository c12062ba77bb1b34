// navbus-sensor-sim configuration: YAML in the units written in its comments, converted to SI
// here, once.
#pragma once

#include <cstdint>
#include <string>

#include <yaml-cpp/yaml.h>

#include "navbus/sim/stationary_source.hpp"

namespace navbus::sensor_sim {

enum class Pacing { kRealTime, kFast };

struct SimConfig {
  sim::StationarySourceConfig source;
  bool start_now{true};    ///< start at the current GPS time (real time), else start_gps_ns
  double duration_s{0.0};  ///< 0: until stopped
  Pacing pacing{Pacing::kRealTime};
  double wait_for_readers_s{10.0};  ///< wait this long for readers before publishing
  /// Readers to wait for before publishing, per topic.
  struct MinReaders {
    int imu{1}, raw_imu{0}, gnss{1}, star_tracker{1};
  } min_readers;
  std::uint32_t imu_sensor_id{1};
  std::uint32_t gnss_receiver_id{1};
  std::uint32_t star_tracker_id{1};
  bool publish_raw{true};
  bool publish_gnss{true};
  bool publish_star_tracker{true};
};

/// Throws bus::ConfigError naming the key and value on any invalid entry.
SimConfig parseSimConfig(const YAML::Node& root);

}  // namespace navbus::sensor_sim
