#include "navbus/fault_manager/repeat_guard.hpp"

#include <algorithm>
#include <cmath>

namespace navbus::fault_manager {

int RepeatGuard::recentDecisions(const FaultSourceKey& key, std::int64_t time_ns) {
  std::deque<std::int64_t>& times = decided_ns_[key];
  const auto window_ns = static_cast<std::int64_t>(std::llround(config_.window_s * 1e9));
  while (!times.empty() && time_ns - times.front() > window_ns) times.pop_front();
  return static_cast<int>(times.size());
}

RepeatGuard::Verdict RepeatGuard::onDetection(std::int64_t time_ns,
                                              const std::vector<FaultSourceKey>& sources) {
  const bool escalated = std::any_of(sources.begin(), sources.end(),
                                     [this](const auto& key) { return escalated_.count(key) > 0; });
  if (escalated) {
    ++suppressed_;
    return Verdict::kSuppress;
  }
  int most = 0;
  for (const FaultSourceKey& key : sources) most = std::max(most, recentDecisions(key, time_ns));
  if (most >= config_.escalate_after) {
    escalated_.insert(sources.begin(), sources.end());
    ++escalations_;
    return Verdict::kEscalate;
  }
  for (const FaultSourceKey& key : sources) decided_ns_[key].push_back(time_ns);
  return Verdict::kDecide;
}

}  // namespace navbus::fault_manager
