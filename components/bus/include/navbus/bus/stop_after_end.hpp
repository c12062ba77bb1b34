// `--exit-when-ended`: a participant that stops by itself once the data has ended, i.e. its
// IMU stream's writer disposed the instance (the simulator and `navbus replay` do at the end
// of their data), after a grace period for what is still in flight (the filter's last
// solutions, its last diagnostics). Used where nobody sends SIGTERM: the compose demo.
#pragma once

#include <chrono>
#include <optional>

#include <CLI/CLI.hpp>

#include "navbus/bus/participant.hpp"

namespace navbus::bus {

class StopAfterEnd {
 public:
  StopAfterEnd(Participant& participant, std::chrono::nanoseconds grace);
  /// The data ended now; the participant stops `grace` later.
  void ended();

 private:
  Participant& participant_;
  std::chrono::nanoseconds grace_;
  std::optional<std::chrono::steady_clock::time_point> ended_at_;
};

/// The grace period of --exit-when-ended.
inline constexpr std::chrono::seconds kStopAfterEndGrace{2};

/// Adds --exit-when-ended to a participant's command line.
void addExitWhenEndedOption(CLI::App& app, bool& exit_when_ended);

}  // namespace navbus::bus
