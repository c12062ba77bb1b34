// navbus-filter configuration, converted to SI here.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <yaml-cpp/yaml.h>

#include "navbus/bus/topics.hpp"
#include "navbus/core/navigation_engine.hpp"

namespace navbus::nav_filter {

struct InputConfig {
  std::uint32_t id{1};
  std::int64_t period_ns{0};
};

struct FilterConfig {
  core::EngineConfig engine;  ///< aiding mode, fusion structure, tuning, initial state
  std::uint32_t vehicle_id{1};
  InputConfig imu{1, 10'000'000};
  std::optional<InputConfig> gnss_observations;
  std::optional<InputConfig> gnss_fix;
  std::optional<InputConfig> star_tracker;
  std::int64_t sequencer_max_wait_ns{500'000'000};
  /// QoS profile of the solution writer (qos/navbus_qos.xml): navbus_solution_writer, or
  /// navbus_solution_writer_lossless for recording fast-paced runs.
  std::string solution_writer_profile{bus::profile::kSolutionWriter};
};

/// Throws bus::ConfigError naming the key and the value on any invalid entry.
FilterConfig parseFilterConfig(const YAML::Node& root);

}  // namespace navbus::nav_filter
