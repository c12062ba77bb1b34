// Bounded history of what the filter processed, for recovery from a fault found late: engine
// snapshots taken at most every `snapshot_period` of data time, and every input and command
// processed since the oldest snapshot kept. A fault command with an estimated onset restores
// the latest snapshot taken before the onset; the inputs before the onset are re-processed,
// the command applies at the onset, and everything that followed is re-processed, so that the
// contamination accumulated since the onset (e.g. a ramping satellite pulled into the position,
// a bias step absorbed into the estimates) is gone rather than slowly forgotten. The engine is
// deterministic, so the result is the same whenever the command arrives, and whatever the
// snapshot period (which only sets how much is re-processed). Pure logic, DDS-free.
#pragma once

#include <algorithm>
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <variant>

#include <navbus_idl/Fault.h>

#include "navbus/core/engine/navigation_engine.hpp"
#include "navbus/core/math/ring_buffer.hpp"

namespace navbus::nav_filter {

template <class Input>
class InputHistory {
 public:
  using Item = Input;

  /// `snapshot_period_ns` is clamped to the span. `expected_items`: the inputs the span holds
  /// (FilterPipeline counts them from the configured periods); the item buffer is made that large
  /// at once, so that it does not allocate while it fills (it still grows if more come).
  InputHistory(std::int64_t span_ns, std::int64_t snapshot_period_ns,
               std::size_t expected_items = 16)
      : span_ns_(span_ns),
        // A period longer than the span would keep older snapshots than the span says.
        snapshot_period_ns_(span_ns > 0 ? std::min(snapshot_period_ns, span_ns)
                                        : snapshot_period_ns),
        snapshots_(span_ns > 0 ? maxSnapshots() : 1),
        items_(span_ns > 0 ? expected_items : 1) {}

  bool enabled() const { return span_ns_ > 0; }

  /// The item the next record() overwrites (one forgotten before), whose storage the caller may
  /// take for a new input first; nullptr if none.
  Item* overwritten() { return enabled() ? items_.nextSlot() : &unkept_; }

  /// Called before `engine` processes `item` at data time `time_ns`; returns the item as kept
  /// (moved in: an epoch's satellites are not copied), which the caller then processes.
  const Item& record(std::int64_t time_ns, Item&& item, const core::NavigationEngine& engine) {
    if (!enabled()) {
      unkept_ = std::move(item);
      return unkept_;
    }
    // Also the first input after the engine initialized: a restore needs an initialized
    // snapshot, and the first one (before the first input) is not.
    if (snapshots_.empty() || time_ns - snapshots_.back().time_ns >= snapshot_period_ns_ ||
        (engine.initialized() && !snapshots_.back().engine.initialized())) {
      const std::size_t first_item = first_index_ + items_.size();
      // The engine owns heap storage: every snapshot slot the span needs (the ring is made that
      // large) is made at the first snapshot, so that the history allocates nothing afterwards,
      // not even while it fills (a no-op once made).
      if (snapshots_.empty()) {
        snapshots_.prefill(maxSnapshots(), [&] {
          return Snapshot{time_ns, latest_ns_, first_item, engine};
        });
      }
      snapshots_.push_back_reusing(
          [&] {
            return Snapshot{time_ns, latest_ns_, first_item, engine};
          },
          [&](Snapshot& s) {
            s.time_ns = time_ns;
            s.inputs_up_to_ns = latest_ns_;
            s.first_item = first_item;
            s.engine = engine;  // copy-assigned: storage reused
          });
    }
    items_.push_back(std::move(item));
    const Item& kept = items_.back();
    latest_ns_ = std::max(latest_ns_, time_ns);
    // Forget snapshots (and the items before them) older than the span, keeping one.
    while (snapshots_.size() > 1 && time_ns - snapshots_[1].time_ns >= span_ns_) {
      snapshots_.pop_front();
    }
    while (first_index_ < snapshots_.front().first_item) {
      items_.pop_front();
      ++first_index_;
    }
    return kept;
  }

  /// Restores the engine to the latest snapshot of an initialized engine taken before any
  /// input at or after `onset_ns` was processed, and returns the items processed since (to be
  /// re-processed by the caller, who records them again: those before the onset first). False
  /// when the history does not reach back to the onset.
  bool rollback(std::int64_t onset_ns, core::NavigationEngine& engine, std::deque<Item>& replay) {
    return restore(engine, replay, [onset_ns](const Snapshot& s) {
      return s.engine.initialized() && s.inputs_up_to_ns < onset_ns;
    });
  }

  /// Restores the engine to the latest snapshot taken before any input at or after `time_ns`
  /// was processed, and returns the inputs processed since (to be merged again with an input
  /// at `time_ns` that came late). Returns the latest data time of the inputs that stay
  /// processed; nothing when the history does not reach back so far.
  std::optional<std::int64_t> rewindBefore(std::int64_t time_ns, core::NavigationEngine& engine,
                                           std::deque<Item>& replay) {
    if (!restore(engine, replay,
                 [time_ns](const Snapshot& s) { return s.inputs_up_to_ns < time_ns; }))
      return std::nullopt;
    return latest_ns_;
  }

  /// The most snapshots the span holds: one per period, the one kept beyond the span, the one
  /// being taken and the one taken when the engine initialized (at most 4096).
  std::size_t maxSnapshots() const {
    if (snapshot_period_ns_ <= 0) return 1;
    return static_cast<std::size_t>(
        std::min<std::int64_t>(span_ns_ / snapshot_period_ns_ + 3, 4096));
  }

 private:
  struct Snapshot {
    std::int64_t time_ns;          ///< data time of the first item after it
    std::int64_t inputs_up_to_ns;  ///< latest data time of the items before it
    std::size_t first_item;        ///< absolute index of that item
    core::NavigationEngine engine;
  };

  /// Restores the latest snapshot `usable` accepts; the items since go to `replay`.
  template <class Usable>
  bool restore(core::NavigationEngine& engine, std::deque<Item>& replay, Usable usable) {
    if (!enabled()) return false;
    for (std::size_t i = snapshots_.size(); i-- > 0;) {
      const Snapshot& s = snapshots_[i];
      if (!usable(s)) continue;
      latest_ns_ = s.inputs_up_to_ns;
      engine = s.engine;
      replay.clear();
      const std::size_t from = s.first_item - first_index_;
      for (std::size_t k = from; k < items_.size(); ++k) replay.push_back(std::move(items_[k]));
      items_.truncate(from);
      snapshots_.truncate(i);
      return true;
    }
    return false;
  }

  std::int64_t span_ns_;
  std::int64_t snapshot_period_ns_;
  // Ring buffers: in the steady state (as many forgotten as recorded) nothing is allocated.
  core::RingBuffer<Snapshot> snapshots_;
  core::RingBuffer<Item> items_;
  Item unkept_{};               ///< the item being processed when the history is off
  std::size_t first_index_{0};  ///< absolute index of items_.front()
  /// Latest data time of the items recorded (the merge releases in time order, but a command
  /// applied at once is recorded at the engine's time, which may be earlier).
  std::int64_t latest_ns_{std::numeric_limits<std::int64_t>::min()};
};

}  // namespace navbus::nav_filter
