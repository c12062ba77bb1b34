// `--exit-when-ended`: a participant that stops by itself once the data has ended, i.e. its
// IMU stream's writer disposed the instance (the simulator and `navbus replay` do at the end
// of their data), after a grace period for what is still in flight (the filter's last
// solutions, its last diagnostics). Used where nobody sends SIGTERM: the compose demo.
//
// A writer that left the bus without that notice (killed; or its dispose lost on the way to a
// best-effort reader, the fault manager's watchdog) can send no more data either: once every
// IMU writer has lost its liveliness, the participant stops after the same grace, unless one
// is alive again before it ends (this participant's own stall can make its view stale).
#pragma once

#include <chrono>
#include <optional>

#include <CLI/CLI.hpp>

#include "navbus/bus/participant.hpp"

namespace navbus::bus {

class StopAfterEnd {
 public:
  StopAfterEnd(Participant& participant, std::chrono::nanoseconds grace);
  /// The data ended now (announced by the writer); the participant stops `grace` later.
  void ended();
  /// The IMU writers' liveliness changed: none alive starts the grace, one alive again before
  /// it ends cancels it (an announced end is not cancelled).
  void writersAlive(bool alive);

 private:
  Participant& participant_;
  std::chrono::nanoseconds grace_;
  std::optional<std::chrono::steady_clock::time_point> stop_from_;
  bool announced_{false};
};

/// The grace period of --exit-when-ended.
inline constexpr std::chrono::seconds kStopAfterEndGrace{2};

/// Adds --exit-when-ended to a participant's command line.
void addExitWhenEndedOption(CLI::App& app, bool& exit_when_ended);

}  // namespace navbus::bus
