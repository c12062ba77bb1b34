// `navbus health PARTICIPANT`: whether a participant is alive and working, from its own health
// reports on navbus/health (a container healthcheck, a script's wait). Exit 0 when a report
// from it arrives within the timeout in state RUNNING (or DEGRADED: working with a lost input),
// 1 otherwise (no report, STARTING or STOPPING), printing the state.
#pragma once

#include <string>

#include "navbus/bus/participant.hpp"

namespace navbus::tool {

struct HealthCheckOptions {
  std::string participant;  ///< Health.participant, e.g. navbus-filter
  double timeout_s{5.0};
};

int runHealthCommand(const bus::Participant::Options& participant, const HealthCheckOptions& o,
                     bus::ShutdownSignal& shutdown);

}  // namespace navbus::tool
