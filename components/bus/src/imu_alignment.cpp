#include "navbus/bus/imu_alignment.hpp"

#include <algorithm>

namespace navbus::bus {

ImuUnitAligner::Added ImuUnitAligner::add(int unit, const core::ImuIncrement& inc) {
  if (inc.time_ns <= released_ns_) return Added::kLate;
  const auto u = static_cast<std::size_t>(unit);
  if (inc.time_ns <= latest_ns_[u]) return Added::kRepeated;
  queues_[u].push_back(inc);
  latest_ns_[u] = inc.time_ns;
  return Added::kTaken;
}

std::int64_t ImuUnitAligner::oldest(std::uint32_t& present) const {
  std::int64_t t = -1;
  present = 0;
  for (int u = 0; u < units_; ++u) {
    const auto& q = queues_[static_cast<std::size_t>(u)];
    if (q.empty()) continue;
    const std::int64_t front = q.front().time_ns;
    if (t < 0 || front < t) {
      t = front;
      present = 0;
    }
    if (front == t) present |= bit(u);
  }
  return t;
}

bool ImuUnitAligner::lost(std::int64_t time_ns, std::uint32_t present) const {
  for (int u = 0; u < units_; ++u) {
    if ((present | ended_) & bit(u)) continue;
    if (latest_ns_[static_cast<std::size_t>(u)] <= time_ns) return false;
  }
  return true;
}

std::size_t ImuUnitAligner::waiting() const {
  std::size_t most = 0;
  for (const auto& q : queues_) most = std::max(most, q.size());
  return most;
}

std::optional<ImuUnitAligner::Sample> ImuUnitAligner::next(std::int64_t up_to_ns) {
  std::uint32_t present = 0;
  const std::int64_t t = oldest(present);
  if (t < 0 || t > up_to_ns) return std::nullopt;
  if (present != all() && !lost(t, present) && waiting() <= depth_) return std::nullopt;
  return take(t, present);
}

std::optional<ImuUnitAligner::Sample> ImuUnitAligner::flushNext() {
  std::uint32_t present = 0;
  const std::int64_t t = oldest(present);
  if (t < 0) return std::nullopt;
  return take(t, present);
}

ImuUnitAligner::Sample ImuUnitAligner::take(std::int64_t time_ns, std::uint32_t present) {
  Sample s;
  s.time_ns = time_ns;
  s.present = present;
  for (int u = 0; u < units_; ++u) {
    if ((present & bit(u)) == 0) continue;
    auto& q = queues_[static_cast<std::size_t>(u)];
    s.units[static_cast<std::size_t>(u)] = q.front();
    q.pop_front();
  }
  released_ns_ = time_ns;
  return s;
}

void ImuUnitAligner::clear() {
  for (auto& q : queues_) q.clear();
  latest_ns_.fill(0);
  ended_ = 0;
  released_ns_ = -1;
}

}  // namespace navbus::bus
