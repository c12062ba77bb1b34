// Waiting on the bus from a tool: spin the participant's waitset until a condition holds.
#pragma once

#include <functional>

#include "navbus/bus/participant.hpp"

namespace navbus::tool {

/// Spins `p` until `done()`, a stop request, or `timeout_s`; returns done().
bool spinUntil(bus::Participant& p, double timeout_s, const std::function<bool()>& done);

}  // namespace navbus::tool
