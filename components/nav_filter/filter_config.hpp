// navbus-filter configuration, converted to SI here.
#pragma once

#include <cstdint>
#include <optional>

#include <yaml-cpp/yaml.h>

#include "navbus/core/tightly_coupled_ekf.hpp"

namespace navbus::nav_filter {

struct InputConfig {
  std::uint32_t id{1};
  std::int64_t period_ns{0};
};

/// What navbus-filter estimates.
enum class Estimator {
  kInertialOnly,   ///< free strapdown mechanization (GNSS and star tracker validated, unused)
  kTightlyCoupled  ///< 17-state EKF with pseudoranges and rates (seed 000), centralized
};

struct FilterConfig {
  Estimator estimator{Estimator::kInertialOnly};
  core::TightlyCoupledConfig tightly_coupled;
  double initial_clock_bias_m{0.0};
  double initial_clock_drift_mps{0.0};
  std::uint32_t vehicle_id{1};
  std::int64_t solution_period_ns{100'000'000};
  core::NavState initial_state;  ///< time is taken from the first increment
  InputConfig imu{1, 10'000'000};
  std::optional<InputConfig> gnss_observations;
  std::optional<InputConfig> gnss_fix;
  std::optional<InputConfig> star_tracker;
  std::int64_t sequencer_max_wait_ns{500'000'000};
};

FilterConfig parseFilterConfig(const YAML::Node& root);

}  // namespace navbus::nav_filter
