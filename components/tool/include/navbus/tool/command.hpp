// `navbus command KIND ...`: sends one FilterCommand (any kind, any field) to navbus-filter, as
// an operator would, and waits for the filter's answer on navbus/nav/command_outcome: the filter
// range-checks it and applies, clamps or refuses it (its log, summary and health say so too);
// commands are obeyed only from the issuers in its configuration (`operator` by default).
#pragma once

#include <cstdint>
#include <string>

#include <navbus_idl/Fault.h>

#include "navbus/bus/participant.hpp"

namespace navbus::tool {

/// The command's fields as typed: enums by name (with or without their CMD_/SCOPE_/SOURCE_/
/// FUSION_/MODE_ prefix), numbers in the IDL's units (SI).
struct CommandOptions {
  std::string kind;  ///< CommandKind, e.g. EXCLUDE_SATELLITE
  std::uint32_t vehicle_id{1};
  std::uint16_t sv_id{0};
  std::string scope{"ALL"};  ///< SatelliteScope
  std::string sensor;        ///< FaultSource, e.g. ACCELEROMETER; empty: none needed
  std::uint32_t sensor_id{0};
  std::uint16_t axis{0};
  double bias{0.0};              ///< [m/s^2 or rad/s, body]
  double bias_sigma{0.0};        ///< [m/s^2 or rad/s]
  std::string fusion;            ///< FusionStructure for SELECT_FUSION
  std::string mode;              ///< FilterMode for SELECT_MODE
  std::uint64_t time_gps_ns{0};  ///< data time the command refers to; 0: at once
  std::uint64_t onset_time_gps_ns{0};
  std::uint32_t decision_id{0};
  std::string issuer{"operator"};
  std::uint64_t command_id{0};   ///< 0: this run's start time [ns] (increasing across runs)
  double match_timeout_s{10.0};  ///< wait this long for the filter's reader, then its answer
  /// Write once this many readers matched (the filter, and recorders that must have it: a
  /// reader that matches after this tool ended never gets the command).
  std::uint32_t min_readers{1};
};

/// Builds the command; throws bus::ConfigError naming the option and the value.
navbus::FilterCommand buildCommand(const CommandOptions& options, std::uint64_t run_id_ns);

/// Returns an exit code: 0 once the addressed filter applied the command (or clamped a value of
/// it), runtime error if it refused it, or if no reader matched or no answer came within the
/// timeout.
int runCommandCommand(const bus::Participant::Options& participant, const CommandOptions& options,
                      bus::ShutdownSignal& shutdown);

}  // namespace navbus::tool
