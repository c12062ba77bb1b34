// Command-line and configuration handling common to every navbus executable.
#pragma once

#include <functional>
#include <string>

#include <yaml-cpp/yaml.h>
#include <CLI/CLI.hpp>

#include "navbus/bus/participant.hpp"

namespace navbus::bus {

/// Exit codes of every navbus executable.
enum ExitCode : int {
  kExitOk = 0,
  kExitRuntimeError = 1,  ///< failure while running (e.g. a test expectation in a tool)
  kExitConfigError = 2,   ///< bad command line or configuration
  kExitDdsError = 3,      ///< a DDS entity could not be created (profile, QoS, transport)
};

struct CommonOptions {
  std::string config_file;          ///< YAML configuration
  int domain_id{-1};                ///< -1: from the configuration (default 0)
  std::string qos_file;             ///< empty: configuration, environment or installed default
  std::string participant_profile;  ///< empty: configuration or the loopback profile
  std::string security_identity;    ///< empty: configuration (none by default)
  std::string discovery_server;     ///< empty: configuration, else the profile's server
  bool ros2_names{false};           ///< --ros2 (or the configuration's ros2_names)
  std::string log_level{"info"};
};

/// Adds --config, --domain, --qos, --profile, --identity and --log-level.
void addCommonOptions(CLI::App& app, CommonOptions& options, bool config_required);

/// Participant options: command line first, then the configuration's keys domain_id,
/// qos_file, participant_profile, security_identity, discovery_server, health_period_s and the
/// realtime block, then defaults.
Participant::Options participantOptions(const CommonOptions& options, const YAML::Node& config,
                                        const std::string& name);

/// Parses the command line, sets up logging, loads the configuration and runs `body`,
/// turning exceptions into a message and an exit code (never an abort).
int runMain(CLI::App& app, int argc, char** argv, CommonOptions& options,
            const std::function<int(const YAML::Node& config)>& body);

}  // namespace navbus::bus
