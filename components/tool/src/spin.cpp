#include "navbus/tool/spin.hpp"

#include <chrono>

namespace navbus::tool {

bool spinUntil(bus::Participant& p, double timeout_s, const std::function<bool()>& done) {
  using SteadyClock = std::chrono::steady_clock;
  const auto end = SteadyClock::now() + std::chrono::duration<double>(timeout_s);
  while (!done() && !p.stopping() && SteadyClock::now() < end)
    p.spinOnce(std::chrono::milliseconds(5));
  return done();
}

}  // namespace navbus::tool
