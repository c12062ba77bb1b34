#include "navbus/bus/stream_end.hpp"

namespace navbus::bus {

void StreamEndCounter::taken(const WriterId& writer, std::int64_t rtps_seq) {
  last_taken_[writer] = rtps_seq;
}

std::uint64_t StreamEndCounter::disposed(const WriterId& writer, std::int64_t rtps_seq) {
  const auto it = last_taken_.find(writer);
  if (it == last_taken_.end()) return 0;
  const std::int64_t missed = rtps_seq - it->second - 1;
  it->second = rtps_seq;  // a writer with several instances disposes each in turn
  return missed > 0 ? static_cast<std::uint64_t>(missed) : 0;
}

}  // namespace navbus::bus
