#include "navbus/bus/stop_after_end.hpp"

#include <spdlog/spdlog.h>

namespace navbus::bus {

namespace {
long long milliseconds(std::chrono::nanoseconds d) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(d).count();
}
}  // namespace

StopAfterEnd::StopAfterEnd(Participant& participant, std::chrono::nanoseconds grace)
    : participant_(participant), grace_(grace) {
  participant_.addTimer(std::chrono::milliseconds(100), [this] {
    if (stop_from_ && std::chrono::steady_clock::now() >= *stop_from_ + grace_) participant_.stop();
  });
}

void addExitWhenEndedOption(CLI::App& app, bool& exit_when_ended) {
  app.add_flag("--exit-when-ended", exit_when_ended,
               "stop by itself 2 s after the IMU stream's writer announced the end of its data "
               "(the simulator and navbus replay do), or 2 s after every IMU writer left the "
               "bus without announcing it (unless one comes back meanwhile), e.g. in the "
               "compose demo");
}

void StopAfterEnd::ended() {
  if (announced_) return;
  announced_ = true;
  if (!stop_from_) stop_from_ = std::chrono::steady_clock::now();
  spdlog::info("the IMU stream ended; stopping in {} ms (--exit-when-ended)", milliseconds(grace_));
}

void StopAfterEnd::writersAlive(bool alive) {
  if (announced_) return;
  if (!alive && !stop_from_) {
    stop_from_ = std::chrono::steady_clock::now();
    spdlog::warn(
        "every IMU writer left the bus without announcing the end of its data; stopping in {} "
        "ms unless one comes back (--exit-when-ended)",
        milliseconds(grace_));
  } else if (alive && stop_from_) {
    stop_from_.reset();
    spdlog::info("an IMU writer is alive again: not stopping (--exit-when-ended)");
  }
}

}  // namespace navbus::bus
