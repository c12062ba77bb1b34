// The dither detector of the fault pipeline (seed 003): runs core::DitherMonitor on the raw
// high-rate IMU stream of one IMU and turns a channel's fault bit into a decision (detector
// "dither-fft": the axis, the peak found, the lines expected) and, when the configuration asks
// for it, a CMD_FAIL_SENSOR_AXIS command; a channel passing again is reported as cleared
// (a decision only: trusting the axis again is an operator's command).
#pragma once

#include <cstdint>
#include <string>

#include <navbus_idl/Imu.h>

#include "navbus/bus/validation.hpp"
#include "navbus/core/integrity/dither_monitor.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/fault_output.hpp"

namespace navbus::fault_manager {

class DitherDetector {
 public:
  explicit DitherDetector(const DitherDetectorConfig& config);

  /// One raw block as received. Blocks of other IMUs, at another sample rate, or failing
  /// validation are counted and not monitored; a gap in the samples' times drops the window
  /// being filled (counted by the monitor), it never raises an alarm.
  void onRawBlock(const navbus::ImuRawBlock& block, FaultOutput& out);

  struct Counters {
    std::uint64_t blocks{0}, other_imus{0}, wrong_rate{0}, invalid{0};
    std::uint64_t detections{0}, cleared{0};
  };
  const Counters& counters() const { return counters_; }
  const core::DitherMonitor& monitor() const { return monitor_; }
  std::string summary() const;

 private:
  void report(int channel, const core::DitherWindow& w, FaultOutput& out);

  DitherDetectorConfig config_;
  core::DitherMonitor monitor_;
  std::int64_t period_ns_;
  bus::ValidationLimits limits_;
  Counters counters_;
};

}  // namespace navbus::fault_manager
