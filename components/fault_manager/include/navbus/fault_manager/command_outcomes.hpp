// Whether the fault loop is closed: the filter answers every command with a
// FilterCommandOutcome. This class keeps those of this fault manager's own commands (its issuer
// and run), counts them, and says the loop is degraded while the latest one was not applied as
// sent (refused, or clamped to a limit: the fault it answered is not cured), until a later
// command of this run is applied. A stream command the filter refuses because it does not fuse
// that stream (REJECT_UNEXPECTED_SOURCE: e.g. a redundant receiver's epochs, read only by the
// cross-receiver test) leaves nothing uncured: counted, not degraded. Pure logic.
#pragma once

#include <cstdint>
#include <string>

#include <navbus_idl/Fault.h>

namespace navbus::fault_manager {

class CommandOutcomes {
 public:
  CommandOutcomes(std::string issuer, std::uint64_t run_id)
      : issuer_(std::move(issuer)), run_id_(run_id) {}

  /// An outcome from the filter; false if it answers another issuer's (or run's) command.
  bool onOutcome(const navbus::FilterCommandOutcome& o);
  /// The latest outcome of this run's commands was a refusal or a clamp.
  bool degraded() const { return degraded_; }
  std::uint64_t applied() const { return applied_; }
  std::uint64_t clamped() const { return clamped_; }
  std::uint64_t refused() const { return refused_; }
  /// Stream commands refused as not the filter's streams (within refused()).
  std::uint64_t notItsStreams() const { return not_its_streams_; }
  /// The outcome refuses a stream command because the filter does not fuse that stream.
  static bool notItsStream(const navbus::FilterCommandOutcome& o);

 private:
  std::string issuer_;
  std::uint64_t run_id_;
  std::uint64_t latest_command_id_{0};
  bool degraded_{false};
  std::uint64_t applied_{0}, clamped_{0}, refused_{0}, not_its_streams_{0};
};

}  // namespace navbus::fault_manager
