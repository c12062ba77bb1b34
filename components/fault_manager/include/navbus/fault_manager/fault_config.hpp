// navbus-fault-manager configuration (YAML), converted to SI here. Unknown keys in the
// sections below are errors naming the key, so that a misspelled setting is not ignored.
#pragma once

#include <cstdint>

#include <yaml-cpp/yaml.h>

#include "navbus/core/integrity/dither_monitor.hpp"
#include "navbus/core/integrity/glr.hpp"
#include "navbus/fault_manager/repeat_guard.hpp"

namespace navbus::fault_manager {

struct GlrDetectorConfig {
  bool enabled{true};
  core::GlrConfig glr;
  bool exclude_satellites{true};  ///< command the exclusion of an isolated satellite
  bool compensate_imu{true};      ///< command the compensation of an isolated IMU bias step
  /// The compensation waits until the magnitude's standard error is at most this share of it
  /// (or the onset leaves the window); the decision itself is published at detection.
  double compensation_relative_sigma{0.05};
  /// Readmission of an excluded satellite (still monitored by the filter, outside the GLR):
  /// every normalized innovation |eps| / sqrt(V) of its rows at most `readmit_sigma` for
  /// `readmit_after_s` of consecutive epochs.
  double readmit_sigma{3.0};
  double readmit_after_s{30.0};
  /// Repeated decisions on one source escalate once (repeat_guard.hpp).
  RepeatGuardConfig repeats;
};

struct DitherDetectorConfig {
  bool enabled{false};
  std::uint32_t imu_id{1};  ///< the raw stream monitored (ImuRawBlock.sensor_id)
  core::DitherMonitorConfig monitor;
  bool fail_axes{true};  ///< command CMD_FAIL_SENSOR_AXIS for a failed axis
};

struct FaultManagerConfig {
  std::uint32_t vehicle_id{1};  ///< the filter monitored and commanded
  GlrDetectorConfig glr;
  DitherDetectorConfig dither;
};

/// Throws bus::ConfigError naming the key and the value on any invalid or unknown entry.
FaultManagerConfig parseFaultManagerConfig(const YAML::Node& root);

}  // namespace navbus::fault_manager
