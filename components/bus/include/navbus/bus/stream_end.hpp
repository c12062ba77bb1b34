// The samples a reader never received at the end of a stream. A best-effort reader that falls
// behind skips samples; a skip is counted as a sequence gap when a later sample of the stream
// arrives, but the last samples before the writer's dispose (the announced end) have no later
// sample. The writer's RTPS sequence numbers count every change it wrote, data and dispose
// alike, so the changes between the last one taken and the dispose are the ones missed.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>

#include "navbus/bus/writer_gate.hpp"

namespace navbus::bus {

/// How long a writer that announced the end of its streams (disposed them and waited for the
/// reliable readers' acknowledgments) stays on the bus before it leaves. Best-effort readers
/// (the fault manager's watchdogs) acknowledge nothing: a writer that left at once could be
/// gone before its dispose was taken there, and the stream was judged lost, not ended (3 of 4
/// streams in one compose run under DDS Security; one replay in four under AddressSanitizer).
inline constexpr std::chrono::milliseconds kEndOfStreamLinger{300};

/// How long a source waits, once its writers see every reader it waits for, before its first
/// sample. A writer sees a reader matched when the reader's announcement has arrived; the
/// reader matches the writer when the writer's has, which can come later on a loaded machine,
/// and a volatile reliable reader (Fast DDS 2.9) drops what it receives before, for good: the
/// stream's first samples are lost to it (counted there from the sequence numbers: the
/// parity test's "not received before a unit's first", the filter's sequence gaps at the
/// start).
inline constexpr std::chrono::milliseconds kStartSettle{300};

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
