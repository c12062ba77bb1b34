// Whether this process was not running: a participant's loop runs at least every `period`
// (its timer), so a gap of `stall` or more between two of its turns means the process was
// stopped (SIGSTOP, a debugger), starved of CPU, or its VM was not scheduled. What it then sees
// first is stale: its peers' silences and lost liveliness were its own. Pure logic: the caller
// supplies its steady clock.
#pragma once

#include <cstdint>
#include <optional>

namespace navbus::bus {

class StallDetector {
 public:
  /// The loop runs at least every 20 ms; a gap of 200 ms is a stall.
  static constexpr std::int64_t kLoopPeriodNs = 20'000'000;
  static constexpr std::int64_t kStallNs = 10 * kLoopPeriodNs;

  /// The loop is running at `now_ns`: the length of the stall that just ended, if any.
  std::optional<std::int64_t> running(std::int64_t now_ns) {
    const std::int64_t gap = last_ns_ < 0 ? 0 : now_ns - last_ns_;
    last_ns_ = now_ns;
    if (gap < kStallNs) return std::nullopt;
    return gap;
  }

 private:
  std::int64_t last_ns_{-1};
};

}  // namespace navbus::bus
