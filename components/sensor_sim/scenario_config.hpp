// navbus-sensor-sim scenario files: YAML in the units of the papers' tables (written in the key
// names and comments), converted to SI here, once. See scenarios/*.yaml and the README.
#pragma once

#include <cstdint>
#include <string>

#include <yaml-cpp/yaml.h>

#include "navbus/sim/scenario_source.hpp"

namespace navbus::sensor_sim {

enum class Pacing { kRealTime, kFast };

struct SimConfig {
  sim::ScenarioConfig scenario;
  bool start_now{true};    ///< start at the current GPS time (real time), else the configured time
  double duration_s{0.0};  ///< 0: until stopped (bus) or the end of the segments (files)
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
