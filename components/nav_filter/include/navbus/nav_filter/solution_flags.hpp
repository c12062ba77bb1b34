// What navbus-filter's solutions say about its streams and its fault monitor, beside the
// engine's own status: FAULT_*_STREAM_LOST bits set and cleared by stream commands
// (CMD_EXCLUDE_STREAM / CMD_READMIT_STREAM), and FAULT_NO_FAULT_MONITOR while no fault
// monitor is alive. Either makes the participant DEGRADED. Changes are logged and counted.
// DDS-free.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <navbus_idl/Fault.h>

namespace navbus::nav_filter {

class SolutionFlags {
 public:
  /// The ids of the streams this filter fuses (nullopt: it has no such input).
  struct InputIds {
    std::uint32_t imu{0};
    std::optional<std::uint32_t> gnss_observations, gnss_fix, star_tracker;
    std::optional<std::uint32_t> second_gnss_observations;  ///< a second fused receiver
  };
  /// The stream-lost flag a stream command concerns, only for a stream this filter fuses (its
  /// IMU, its receiver's epochs or fixes, its star tracker: another receiver of a redundant
  /// installation falling silent is not this filter's loss); nullopt for any other.
  static std::optional<std::uint32_t> streamFlag(const navbus::FilterCommand& c,
                                                 const InputIds& ids);
  /// Sets (CMD_EXCLUDE_STREAM) or clears (CMD_READMIT_STREAM) `flag` for the command's stream,
  /// logged: a flag two streams share (two fused receivers) stays while either is lost.
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
  /// A stream lost (source, id) and its flag.
  struct LostStream {
    int source;
    std::uint32_t id;
    std::uint32_t flag;
  };
  std::vector<LostStream> lost_;
  std::uint32_t stream_flags_{0};    ///< FAULT_*_STREAM_LOST bits of lost_
  std::uint32_t monitor_flags_{0};   ///< FAULT_NO_FAULT_MONITOR while no fault monitor is alive
  std::uint64_t monitor_losses_{0};  ///< times the fault monitor was found not alive
};

}  // namespace navbus::nav_filter
