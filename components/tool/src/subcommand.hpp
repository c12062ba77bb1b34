// One `navbus` subcommand: its options on the command line and what it runs. main.cpp
// registers every subcommand and runs the one the user chose; offline subcommands run without
// a DDS participant.
#pragma once

#include <memory>
#include <vector>

#include <CLI/CLI.hpp>

#include "navbus/bus/participant.hpp"

namespace navbus::tool::cli {

class Subcommand {
 public:
  virtual ~Subcommand() = default;
  /// Registers the subcommand and its options.
  virtual void add(CLI::App& app) = 0;
  /// True when the command line chose this subcommand.
  bool chosen() const { return cli_ != nullptr && cli_->parsed(); }
  /// False for offline work (offline, montecarlo, rinex, import, benchmark): no DDS participant at
  /// all.
  virtual bool usesBus() const { return true; }
  /// Inspection tools (topics, echo, record) see every endpoint under a discovery server, not
  /// only their matches.
  virtual bool inspectsBus() const { return false; }
  /// Runs the chosen subcommand and returns its exit code; `options` are the participant's
  /// (unused offline).
  virtual int run(bus::Participant::Options& options, bus::ShutdownSignal& shutdown) = 0;

 protected:
  CLI::App* cli_{nullptr};
};

using Subcommands = std::vector<std::unique_ptr<Subcommand>>;

/// topics, echo, record, recover (inspect_commands.cpp).
void addInspectionSubcommands(Subcommands& out);
/// replay, health, command, latency (bus_commands.cpp).
void addBusSubcommands(Subcommands& out);
/// offline, montecarlo, rinex (evaluation_commands.cpp).
void addEvaluationSubcommands(Subcommands& out);
/// import, allan, benchmark real-car (real_data_commands.cpp).
void addRealDataSubcommands(Subcommands& out);
/// foxglove: the bus served to Foxglove (foxglove_command.cpp).
void addFoxgloveSubcommand(Subcommands& out);

}  // namespace navbus::tool::cli
