// navbus: the user's tool for the bus (topics, echo, record, replay, command, health,
// latency) and for offline work (offline, montecarlo, rinex, import,
// benchmark). Each subcommand's options and
// run are in *_commands.cpp; main registers them and runs the one chosen.
#include "navbus/bus/app.hpp"
#include "navbus/bus/config.hpp"
#include "subcommand.hpp"

namespace nb = navbus;

int main(int argc, char** argv) {
  nb::bus::ShutdownSignal shutdown;
  CLI::App app{"navbus: inspect and record the navbus DDS bus; offline evaluation", "navbus"};
  nb::bus::CommonOptions common;
  nb::bus::addCommonOptions(app, common, false);
  app.require_subcommand(1);
  bool publish_health = false;
  app.add_flag("--health", publish_health,
               "publish this tool's own health reports on navbus/health (off: the tool does not "
               "show up in the bus it inspects)");
  app.footer(
      "Exit codes: 0 ok, 1 fewer samples than --count, 2 usage or configuration error, 3 DDS "
      "error.");
  nb::tool::cli::Subcommands subcommands;
  nb::tool::cli::addInspectionSubcommands(subcommands);
  nb::tool::cli::addBusSubcommands(subcommands);
  nb::tool::cli::addEvaluationSubcommands(subcommands);
  nb::tool::cli::addRealDataSubcommands(subcommands);
  nb::tool::cli::addFoxgloveSubcommand(subcommands);
  for (const auto& s : subcommands) s->add(app);

  return nb::bus::runMain(app, argc, argv, common, [&](const YAML::Node& yaml) -> int {
    for (const auto& s : subcommands) {
      if (!s->chosen()) continue;
      if (!s->usesBus()) {
        nb::bus::Participant::Options no_participant;
        return s->run(no_participant, shutdown);
      }
      auto options = nb::bus::participantOptions(common, yaml, "navbus");
      options.publish_health =
          publish_health;  // an inspection tool is not part of what it inspects (a subcommand
                           // that serves the bus, foxglove, turns it on)
      options.dds.discovery_super_client = s->inspectsBus();
      return s->run(options, shutdown);
    }
    return nb::bus::kExitConfigError;  // require_subcommand(1): not reached
  });
}
