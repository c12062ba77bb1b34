// navbus-fault-manager: stream watchdogs on every sensor stream, publishing fault decisions.
#include "fault_manager_node.hpp"
#include "navbus/bus/app.hpp"

namespace nb = navbus;

int main(int argc, char** argv) {
  nb::bus::ShutdownSignal shutdown;
  CLI::App app{
      "navbus-fault-manager: sensor stream watchdogs and fault decisions on the navbus DDS bus",
      "navbus-fault-manager"};
  nb::bus::CommonOptions common;
  nb::bus::addCommonOptions(app, common, false);
  app.footer(
      "Exit codes: 0 stopped by SIGINT/SIGTERM, 1 runtime error, 2 configuration error, 3 DDS "
      "error.");
  return nb::bus::runMain(app, argc, argv, common, [&](const YAML::Node& yaml) {
    nb::bus::Participant participant(
        nb::bus::participantOptions(common, yaml, "navbus-fault-manager"), shutdown);
    nb::fault_manager::FaultManagerNode node(participant);
    spdlog::info("running: watching IMU, raw IMU, GNSS and star-tracker streams");
    participant.run();
    spdlog::info("summary: {}\n{}", node.summary(), participant.health().summary());
    return static_cast<int>(nb::bus::kExitOk);
  });
}
