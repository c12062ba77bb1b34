// navbus-filter: the integrated navigation filter participant.
#include <optional>

#include "navbus/bus/app.hpp"
#include "navbus/bus/stop_after_end.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/filter_node.hpp"

namespace nb = navbus;

int main(int argc, char** argv) {
  nb::bus::ShutdownSignal shutdown;
  CLI::App app{"navbus-filter: strapdown navigation filter on the navbus DDS bus", "navbus-filter"};
  nb::bus::CommonOptions common;
  bool exit_when_ended = false;
  nb::bus::addExitWhenEndedOption(app, exit_when_ended);
  nb::bus::addCommonOptions(app, common, true);
  app.footer(
      "Exit codes: 0 stopped by SIGINT/SIGTERM (or --exit-when-ended), 1 runtime error, 2 "
      "configuration error, 3 DDS "
      "error.");
  return nb::bus::runMain(app, argc, argv, common, [&](const YAML::Node& yaml) {
    const nb::nav_filter::FilterConfig config = nb::nav_filter::parseFilterConfig(yaml);
    nb::bus::Participant participant(nb::bus::participantOptions(common, yaml, "navbus-filter"),
                                     shutdown);
    nb::nav_filter::FilterNode node(participant, config);
    spdlog::info("running: vehicle {}, solution every {} ms, IMU sensor {}", config.vehicle_id,
                 config.engine.solution_period_ns / 1'000'000, config.imu.id);
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
