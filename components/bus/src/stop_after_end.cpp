#include "navbus/bus/stop_after_end.hpp"

#include <spdlog/spdlog.h>

namespace navbus::bus {

StopAfterEnd::StopAfterEnd(Participant& participant, std::chrono::nanoseconds grace)
    : participant_(participant), grace_(grace) {
  participant_.addTimer(std::chrono::milliseconds(100), [this] {
    if (ended_at_ && std::chrono::steady_clock::now() >= *ended_at_ + grace_) participant_.stop();
  });
}

void addExitWhenEndedOption(CLI::App& app, bool& exit_when_ended) {
  app.add_flag("--exit-when-ended", exit_when_ended,
               "stop by itself 2 s after the IMU stream's writer announced the end of its data "
               "(the simulator and navbus replay do), e.g. in the compose demo");
}

void StopAfterEnd::ended() {
  if (ended_at_) return;
  ended_at_ = std::chrono::steady_clock::now();
  spdlog::info("the IMU stream ended; stopping in {} ms (--exit-when-ended)",
               std::chrono::duration_cast<std::chrono::milliseconds>(grace_).count());
}

}  // namespace navbus::bus
