// navbus-fault-manager configuration (YAML), converted to SI here. Unknown keys in the
// sections below are errors naming the key, so that a misspelled setting is not ignored.
#pragma once

#include <cstdint>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "navbus/bus/imu_alignment.hpp"
#include "navbus/core/integrity/dither_monitor.hpp"
#include "navbus/core/integrity/glr.hpp"
#include "navbus/core/integrity/imu_array_parity.hpp"
#include "navbus/core/integrity/receiver_consistency.hpp"
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

/// The parity detector of redundant IMUs (parity_detector.hpp): the units on the bus, their
/// geometry and noise, converted to SI and per sample here.
struct ParityDetectorConfig {
  bool enabled{false};
  double imu_rate_hz{100.0};  ///< [Hz] every unit's increment rate (samples are time-aligned)
  std::vector<std::uint32_t> sensor_ids;  ///< ImuIncrement.sensor_id of each unit
  std::vector<core::ImuArrayUnit> units;  ///< same order
  core::ImuArrayParityConfig array;
  bool fail_axes{true};  ///< command CMD_FAIL_SENSOR_AXIS (unit, axis) for an isolated instrument
  /// Increments one unit may hold waiting for another's (units are received in any order
  /// between them: a DDS reader hands out one instance's backlog, up to its history per instance
  /// of blocks, before the next's; a unit that has passed a time without its increment lost it).
  /// Beyond this many, the missing unit is silent: the oldest time is dropped, counted, and the
  /// tests restart. 64 bytes an increment (bus/imu_alignment.hpp).
  int alignment_depth{static_cast<int>(bus::ImuUnitAligner::kReaderBacklog)};
};

/// The cross-receiver test of redundant GNSS receivers (receiver_detector.hpp): the receivers on
/// the bus (the first is the reference of the single differences), their antennas, the tests'
/// false-alarm probabilities.
struct ReceiverDetectorConfig {
  bool enabled{false};
  std::vector<std::uint32_t> receiver_ids;                  ///< GnssObservationEpoch.receiver_id
  std::vector<Eigen::Vector3d> antennas_b_m;                ///< same order [m, body]
  core::ParityGlrConfig glr{5, 1, 1e-9, 0.999, 2.0, 0.95};  ///< the satellites' test, per epoch
  core::ReceiverClockConfig clock;
  /// Epoch times that may wait for a receiver before the oldest is dropped (counted): a DDS
  /// reader hands out one receiver's backlog, up to its history's 1000 samples per instance (the
  /// measurement reader profile), before the next's. About 2 kB a time with 12 satellites.
  int alignment_depth{1000};
};

struct FaultManagerConfig {
  std::uint32_t vehicle_id{1};  ///< the filter monitored and commanded
  GlrDetectorConfig glr;
  DitherDetectorConfig dither;
  ParityDetectorConfig parity;
  ReceiverDetectorConfig receivers;
};

/// Throws bus::ConfigError naming the key and the value on any invalid or unknown entry.
FaultManagerConfig parseFaultManagerConfig(const YAML::Node& root);

}  // namespace navbus::fault_manager
