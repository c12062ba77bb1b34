// navbus-fault-manager: stream watchdogs and the GLR of seed 000 on the filter's diagnostics,
// publishing decisions (facts) and filter commands (requests).
#include <optional>

#include "navbus/bus/app.hpp"
#include "navbus/bus/stop_after_end.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/fault_manager_node.hpp"

namespace nb = navbus;

int main(int argc, char** argv) {
  nb::bus::ShutdownSignal shutdown;
  CLI::App app{
      "navbus-fault-manager: stream watchdogs and GLR fault detection and isolation (seed 000) "
      "on the navbus DDS bus; publishes fault decisions and filter commands",
      "navbus-fault-manager"};
  nb::bus::CommonOptions common;
  bool exit_when_ended = false;
  nb::bus::addExitWhenEndedOption(app, exit_when_ended);
  nb::bus::addCommonOptions(app, common, false);
  app.footer(
      "Exit codes: 0 stopped by SIGINT/SIGTERM (or --exit-when-ended), 1 runtime error, 2 "
      "configuration error, 3 DDS "
      "error.");
  return nb::bus::runMain(app, argc, argv, common, [&](const YAML::Node& yaml) {
    const nb::fault_manager::FaultManagerConfig config =
        nb::fault_manager::parseFaultManagerConfig(yaml);
    nb::bus::Participant participant(
        nb::bus::participantOptions(common, yaml, "navbus-fault-manager"), shutdown);
    nb::fault_manager::FaultManagerNode node(participant, config);
    spdlog::info("running: watching IMU, raw IMU, GNSS and star-tracker streams; GLR {}",
                 config.glr.enabled ? "on navbus/nav/diagnostics" : "disabled");
    std::optional<nb::bus::StopAfterEnd> stop_after_end;
    if (exit_when_ended) {
      stop_after_end.emplace(participant, nb::bus::kStopAfterEndGrace);
      node.stopAfterEnd(*stop_after_end);
    }
    participant.run();
    spdlog::info("summary: {}\n{}", node.summary(), participant.health().summary());
    return static_cast<int>(nb::bus::kExitOk);
  });
}
