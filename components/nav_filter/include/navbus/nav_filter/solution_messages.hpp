// navbus-filter's output messages from the engine, and the IDL names of the engine's modes and
// structures: the deterministic NavigationSolution (state, sigmas from the covariance, biases
// with the commanded compensation, mode, fusion, fault flags, start source, protection levels),
// the low-latency output propagated from it, and a text account of the alignment. DDS-free.
#pragma once

#include <cstdint>
#include <string>

#include <navbus_idl/Fault.h>
#include <navbus_idl/Navigation.h>

#include "navbus/core/engine/navigation_engine.hpp"

namespace navbus::nav_filter {

/// The solution at the engine's current state (the engine is initialized). `pipeline_flags`:
/// the stream-lost and fault-monitor flags the pipeline holds, beside the engine's own. The
/// protection levels are filled only while a fault monitor is alive (without its GLR nothing
/// bounds a fault).
navbus::NavigationSolution buildSolution(const core::NavigationEngine& engine,
                                         std::uint32_t vehicle_id, std::uint64_t seq,
                                         std::uint32_t pipeline_flags, bool fault_monitor_alive);
/// The low-latency output: the anchor solution with the propagated state, marked as such.
navbus::NavigationSolution lowLatencySolution(const navbus::NavigationSolution& anchor,
                                              const core::NavState& state, std::uint64_t seq);
/// Where the alignment stands, and what it started from.
std::string describeAlignment(const core::NavigationEngine& engine);

/// Appends the scale of every stream whose noise adapts to a diagnostics message (nothing when
/// adaptive noise is off), and sets the scale on the process noise (1 when it does not adapt).
void appendNoiseScales(const core::NavigationEngine& engine, navbus::FilterDiagnostics& msg);
navbus::MeasurementKind toIdl(core::NoiseStream s);

/// The solution's fault flags for the engine's status bits.
std::uint32_t faultFlags(std::uint32_t engine_status);
navbus::FilterMode toIdl(core::EngineMode mode);
navbus::IntegrityState toIdl(core::IntegrityState s);
navbus::FusionStructure toIdl(core::FusionStructure s, core::AidingMode aiding);
navbus::StartSource toIdl(core::StartSource start, core::AttitudeSource attitude);

}  // namespace navbus::nav_filter
