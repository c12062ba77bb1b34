#include "navbus/bus/imu_alignment.hpp"

namespace navbus::bus {

ImuUnitAligner::Added ImuUnitAligner::add(int unit, const core::ImuIncrement& inc) {
  if (inc.time_ns <= released_ns_) return Added::kLate;
  Sample& s = pending_[inc.time_ns];
  if (s.present & bit(unit)) return Added::kRepeated;
  s.time_ns = inc.time_ns;
  s.present |= bit(unit);
  s.units[static_cast<std::size_t>(unit)] = inc;
  auto& latest = latest_ns_[static_cast<std::size_t>(unit)];
  if (inc.time_ns > latest) latest = inc.time_ns;
  return Added::kTaken;
}

bool ImuUnitAligner::lost(std::int64_t time_ns, std::uint32_t present) const {
  for (int u = 0; u < units_; ++u) {
    if ((present | ended_) & bit(u)) continue;
    if (latest_ns_[static_cast<std::size_t>(u)] <= time_ns) return false;
  }
  return true;
}

std::optional<ImuUnitAligner::Sample> ImuUnitAligner::next(std::int64_t up_to_ns) {
  if (pending_.empty()) return std::nullopt;
  const auto oldest = pending_.begin();
  if (oldest->first > up_to_ns) return std::nullopt;
  if (oldest->second.present != all() && !lost(oldest->first, oldest->second.present) &&
      pending_.size() <= depth_)
    return std::nullopt;
  return take(oldest);
}

std::optional<ImuUnitAligner::Sample> ImuUnitAligner::flushNext() {
  if (pending_.empty()) return std::nullopt;
  return take(pending_.begin());
}

ImuUnitAligner::Sample ImuUnitAligner::take(std::map<std::int64_t, Sample>::iterator it) {
  Sample s = it->second;
  released_ns_ = it->first;
  pending_.erase(it);
  return s;
}

void ImuUnitAligner::clear() {
  pending_.clear();
  latest_ns_.fill(0);
  ended_ = 0;
  released_ns_ = -1;
}

}  // namespace navbus::bus
