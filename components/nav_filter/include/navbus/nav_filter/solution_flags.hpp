// What navbus-filter's solutions say about its streams and its fault monitor, beside the
// engine's own status: FAULT_*_STREAM_LOST bits set and cleared by stream commands
// (CMD_EXCLUDE_STREAM / CMD_READMIT_STREAM), and FAULT_NO_FAULT_MONITOR while no fault
// monitor is alive. Either makes the participant DEGRADED. Changes are logged and counted.
// DDS-free.
#pragma once

#include <cstdint>
#include <optional>

#include <navbus_idl/Fault.h>

namespace navbus::nav_filter {

class SolutionFlags {
 public:
  /// The stream-lost flag a stream command concerns (the IMU stream only with the filter's
  /// `imu_id`); nullopt for a source that is not a stream of this filter.
  static std::optional<std::uint32_t> streamFlag(const navbus::FilterCommand& c,
                                                 std::uint32_t imu_id);
  /// Sets (CMD_EXCLUDE_STREAM) or clears (CMD_READMIT_STREAM) `flag`, logged.
  void applyStreamCommand(const navbus::FilterCommand& c, std::uint32_t flag);
  /// Whether a fault monitor is alive; changes are logged and losses counted.
  void setFaultMonitorAlive(bool alive);

  /// Every flag the solution carries from here.
  std::uint32_t flags() const { return stream_flags_ | monitor_flags_; }
  bool faultMonitorAlive() const { return monitor_flags_ == 0; }
  /// Some stream is lost, or no fault monitor is alive.
  bool degraded() const;
  std::uint64_t monitorLosses() const { return monitor_losses_; }

 private:
  std::uint32_t stream_flags_{0};    ///< FAULT_*_STREAM_LOST bits, set by stream commands
  std::uint32_t monitor_flags_{0};   ///< FAULT_NO_FAULT_MONITOR while no fault monitor is alive
  std::uint64_t monitor_losses_{0};  ///< times the fault monitor was found not alive
};

}  // namespace navbus::nav_filter
