// The samples a reader never received at the end of a stream. A best-effort reader that falls
// behind skips samples; a skip is counted as a sequence gap when a later sample of the stream
// arrives, but the last samples before the writer's dispose (the announced end) have no later
// sample. The writer's RTPS sequence numbers count every change it wrote, data and dispose
// alike, so the changes between the last one taken and the dispose are the ones missed.
#pragma once

#include <cstdint>
#include <map>

#include "navbus/bus/writer_gate.hpp"

namespace navbus::bus {

class StreamEndCounter {
 public:
  /// A change (a data sample) taken from `writer` with its RTPS sequence number.
  void taken(const WriterId& writer, std::int64_t rtps_seq);
  /// The writer's dispose with its RTPS sequence number: the changes of this writer never taken
  /// since the last one taken (0 for a writer nothing was taken from: nothing to count from).
  std::uint64_t disposed(const WriterId& writer, std::int64_t rtps_seq);

 private:
  std::map<WriterId, std::int64_t> last_taken_;
};

}  // namespace navbus::bus
