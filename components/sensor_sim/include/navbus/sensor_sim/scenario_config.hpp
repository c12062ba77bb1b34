// navbus-sensor-sim scenario files: YAML in the units of the papers' tables (written in the key
// names and comments), converted to SI here, once. See scenarios/*.yaml and docs/simulation.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "navbus/sensor_sim/imu_block_batcher.hpp"
#include "navbus/sim/scenario_source.hpp"

namespace navbus::sensor_sim {

enum class Pacing { kRealTime, kFast };

struct SimConfig {
  sim::ScenarioConfig scenario;
  bool start_now{true};    ///< start at the current GPS time (real time), else the configured time
  double duration_s{0.0};  ///< 0: until stopped (bus) or the end of the segments (files)
  Pacing pacing{Pacing::kRealTime};
  /// [s] of data per DDS sample in fast pacing: increments go out as ImuIncrementBlocks, raw
  /// samples in blocks as long, and the epochs, fixes and attitudes of the same frames in
  /// their blocks (bus throughput); 0: one measurement per sample, as in real time, which
  /// always publishes each measurement as it is due.
  double fast_pacing_block_s{0.3};
  double wait_for_readers_s{10.0};  ///< wait this long for readers before publishing
  /// Readers to wait for before publishing, per topic.
  struct MinReaders {
    int imu{1}, raw_imu{0}, gnss{1}, star_tracker{1};
    int gnss_fix{1};  ///< readers of the fixes (the observations' `gnss` unless given apart)
  } min_readers;
  std::uint32_t imu_sensor_id{1};
  /// The sensor ids of the scenario's further IMU units (imu_units), in unit order.
  std::vector<std::uint32_t> extra_imu_sensor_ids;
  std::uint32_t gnss_receiver_id{1};
  /// The receiver ids of the scenario's further GNSS receivers (gnss_units), in receiver order.
  std::vector<std::uint32_t> extra_gnss_receiver_ids;
  std::uint32_t star_tracker_id{1};
  bool publish_raw{true};
  bool publish_gnss{true};
  bool publish_star_tracker{true};
};

/// Throws bus::ConfigError naming the key and value on any invalid entry.
SimConfig parseSimConfig(const YAML::Node& root);

/// Increments per ImuIncrementBlock (fast_pacing_block_s at the IMU rate), 0 when increments
/// go out one per sample (real time, or a block of 0 s). Throws bus::ConfigError naming
/// timing.fast_pacing_block_s when it is not 1..ImuBlockBatcher::kMaxIncrements increments.
std::size_t incrementsPerBlock(const SimConfig& config);

}  // namespace navbus::sensor_sim
