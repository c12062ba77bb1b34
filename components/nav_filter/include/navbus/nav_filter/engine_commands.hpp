// What a FilterCommand does to the navigation engine, once the command gate has passed it
// (command_gate.hpp): the engine call of each kind, and for a command that answers a fault with
// an estimated onset, where the filter is restored to before it is re-processed. DDS-free.
#pragma once

#include <cstdint>

#include <navbus_idl/Fault.h>

#include "navbus/core/engine/navigation_engine.hpp"

namespace navbus::nav_filter {

/// Applies an engine command; false when it does not apply (e.g. a fusion structure or mode
/// the configured aiding does not have). `relearn_sigma`: the gate's sigma of a
/// CMD_RELEARN_BIAS (CommandGate::relearnSigma), unused otherwise.
bool applyEngineCommand(core::NavigationEngine& engine, const navbus::FilterCommand& c,
                        double relearn_sigma, int receiver);
/// The same for a filter with one receiver.
bool applyEngineCommand(core::NavigationEngine& engine, const navbus::FilterCommand& c,
                        double relearn_sigma);
/// The command answers a fault with an estimated onset (exclude a satellite, compensate or
/// re-learn a bias, fail an axis): the filter restores to before the onset and re-processes.
bool answersFaultWithOnset(const navbus::FilterCommand& c);
/// Where to restore for such a command: a satellite is excluded from `onset_margin_ns` before
/// the onset, a bias or axis from the onset itself.
std::int64_t restorePoint(const navbus::FilterCommand& c, std::int64_t onset_margin_ns);
core::SatelliteScope toCore(navbus::SatelliteScope s);

}  // namespace navbus::nav_filter
