// Deterministic merge of several time-stamped input streams (docs/architecture.md, the ordered
// merge).
//
// Fast DDS 2.9 has no DESTINATION_ORDER BY_SOURCE_TIMESTAMP, and samples of different topics
// arrive in any interleaving. The sequencer orders them by (time, stream rank, sensor id) and
// releases a sample only when no expected stream can still deliver an earlier one. Each stream
// declares its period: after a sample at t it promises nothing earlier than t + period, which
// lets a 100 Hz IMU run ahead of a 1 Hz receiver without waiting a whole second. A stream that
// holds the head back for longer than `max_wait` (wall time) is set aside until it delivers
// again: the bounded wait that keeps a dead sensor from stalling navigation (counted in
// timeouts()). A stream is also set aside when it is declared lost. A sporadic stream (commands)
// promises nothing and holds nothing back: its samples are ordered by their time when they
// arrive before that time has been passed, and are late otherwise. A judging stream (the fault
// manager's commands) is sporadic, except where a judgement is owed: once the caller has
// handed its judge something up to a time (owe) and the judge has reported before (judged),
// nothing later is released until the judge reports that time judged, or its own budget runs
// out; so a command answering that data takes its place in the order as it would offline.
// Pure logic: the caller supplies wall time.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

namespace navbus::nav_filter {

struct StreamId {
  int rank{0};  ///< tie-break at equal times: lower rank first (IMU before measurements)
  std::uint32_t sensor_id{0};
  bool operator<(const StreamId& o) const {
    return std::tie(rank, sensor_id) < std::tie(o.rank, o.sensor_id);
  }
  bool operator==(const StreamId& o) const { return rank == o.rank && sensor_id == o.sensor_id; }
};

template <class Payload>
class InputSequencer {
 public:
  struct ExpectedStream {
    StreamId id;
    std::int64_t period_ns;  ///< promise: consecutive samples are at least this far apart
    /// Sporadic: no promise at all (e.g. commands). Its samples take their place in the order
    /// when they arrive in time, but it never holds the others back.
    bool sporadic{false};
    /// Judging (with sporadic): holds the others back behind an owed judgement (owe, judged).
    bool judging{false};
    /// How long this stream may hold the head back [wall ns] (0: the sequencer's max_wait).
    std::int64_t max_wait_ns{0};
    /// Judging: its judge is expected from the start, so the first owed judgement holds the
    /// others back as later ones do (otherwise only once the judge has reported at all).
    bool judged_from_start{false};
  };
  enum class PushResult { kQueued, kLate, kUnexpected };

  InputSequencer(std::vector<ExpectedStream> expected, std::int64_t max_wait_ns) {
    for (const auto& e : expected) {
      State state{e.period_ns, e.sporadic, e.judging};
      state.max_wait_ns = e.max_wait_ns > 0 ? e.max_wait_ns : max_wait_ns;
      state.judged_from_start = e.judging && e.judged_from_start;
      state.seen = state.judged_from_start;
      streams_.emplace(e.id, state);
    }
  }

  /// Queues a sample. kLate: its place in the order was already passed (released);
  /// kUnexpected: the stream is not configured.
  PushResult push(StreamId id, std::int64_t time_ns, Payload payload) {
    auto it = streams_.find(id);
    if (it == streams_.end()) {
      return PushResult::kUnexpected;
    }
    if (late(id, time_ns)) return PushResult::kLate;
    const Key key{time_ns, id};
    if (!it->second.judging) {  // a judging stream is seen and active by its reports
      it->second.seen = true;
      it->second.active = true;
    }
    it->second.last_time_ns = std::max(it->second.last_time_ns, time_ns);
    insertPending(key, std::move(payload));
    return PushResult::kQueued;
  }

  /// True if a sample of `id` at `time_ns` comes after its place in the order was passed.
  bool late(StreamId id, std::int64_t time_ns) const {
    return released_any_ && !(last_released_ < Key{time_ns, id});
  }

  /// True if the stream is configured (push would not answer kUnexpected).
  bool expects(StreamId id) const { return streams_.count(id) > 0; }

  /// A stream declared lost (or ended) does not hold others back; it blocks again once it
  /// delivers. False if the stream is not expected.
  bool setActive(StreamId id, bool active) {
    auto it = streams_.find(id);
    if (it == streams_.end()) return false;
    it->second.active = active;
    return true;
  }

  /// The caller handed the judge of `id` data up to `time_ns` (a judging stream): nothing
  /// later is released before it is judged, once the judge has reported at all.
  void owe(StreamId id, std::int64_t time_ns) {
    auto it = streams_.find(id);
    if (it != streams_.end())
      it->second.owed_up_to_ns = std::max(it->second.owed_up_to_ns, time_ns);
  }
  /// The judge of `id` reports everything up to `time_ns` judged (and every sample it sent
  /// about it arrived): the stream is seen and holds the merge back again where owed.
  void judged(StreamId id, std::int64_t time_ns) {
    auto it = streams_.find(id);
    if (it == streams_.end()) return;
    State& s = it->second;
    s.judged_up_to_ns = std::max(s.judged_up_to_ns, time_ns);
    s.seen = true;
    s.active = true;
  }

  /// Hands every releasable sample, in order, to consume(id, time_ns, payload) (the payload is
  /// the consumer's: it may move from it).
  void release(std::int64_t wall_now_ns,
               const std::function<void(StreamId, std::int64_t, Payload&)>& consume) {
    while (head_ < queue_.size()) {
      const Key key = queue_[head_].first;
      const std::vector<StreamId>& blocking = blockingStreams(key);
      if (!blocking.empty()) {
        if (head_blocked_since_ns_ < 0 || !(blocked_key_ == key)) {
          head_blocked_since_ns_ = wall_now_ns;
          blocked_key_ = key;
        }
        if (!setAsideOverdue(wall_now_ns - head_blocked_since_ns_, blocking)) {
          compact();
          return;
        }
      }
      head_blocked_since_ns_ = -1;
      last_released_ = key;
      released_any_ = true;
      // Moved out first: consume may push more samples (a command in answer to this one),
      // which may move the buffer.
      Payload payload = std::move(queue_[head_++].second);
      consume(key.stream, key.time_ns, payload);
    }
    compact();
  }

  /// A new run of the inputs (their source restarted at an earlier time): forgets the order
  /// released so far and what each stream promised. Only `first` holds the others back at
  /// once; every other stream is set aside until it delivers in the new run (its first samples
  /// may have come before the restart was recognised). The caller releases what is held
  /// first; anything still queued is dropped and its count returned.
  std::size_t newRun(StreamId first) {
    const std::size_t dropped = pending();
    queue_.clear();
    head_ = 0;
    released_any_ = false;
    last_released_ = Key{0, {}};
    head_blocked_since_ns_ = -1;
    for (auto& [id, s] : streams_) {
      s.seen = id == first || s.judged_from_start;
      s.active = s.seen;
      s.last_time_ns = 0;
      s.owed_up_to_ns = -1;
      s.judged_up_to_ns = -1;
    }
    return dropped;
  }

  /// Rewinds the order: `items` (id, time, payload), released before and handed back by the
  /// caller, who restored its state to before them, are pending again, each in its place.
  /// What the caller keeps processed ends at data time `kept_up_to_ns`: samples after it are
  /// no longer late. A late sample within the caller's history is merged so rather than
  /// refused, and the result is the one it would have been in time.
  template <class Items>
  void rewind(std::int64_t kept_up_to_ns, Items& items) {
    for (auto& [id, time_ns, payload] : items) {
      insertPending(Key{time_ns, id}, std::move(payload));
    }
    last_released_ = Key{kept_up_to_ns, StreamId{std::numeric_limits<int>::max(),
                                                 std::numeric_limits<std::uint32_t>::max()}};
    head_blocked_since_ns_ = -1;
  }

  /// The caller was not running (stopped, starved of CPU) until `wall_now_ns`: no stream can
  /// have delivered meanwhile, so the wait for the one holding the head starts again. Silence
  /// counts only while the caller runs.
  void restartWait(std::int64_t wall_now_ns) {
    if (head_blocked_since_ns_ >= 0) head_blocked_since_ns_ = wall_now_ns;
  }

  std::size_t pending() const { return queue_.size() - head_; }
  /// Makes room for `n` pending samples at once, so that a backlog up to that size (a burst
  /// after the caller was starved of CPU) allocates nothing.
  void reserve(std::size_t n) { queue_.reserve(n); }
  /// Times the buffer grew beyond what it had (each an allocation on the caller's thread).
  std::uint64_t grown() const { return grown_; }
  std::uint64_t timeouts() const { return timeouts_; }
  /// Owed judgements not reported within the judging stream's budget.
  std::uint64_t judgementTimeouts() const { return judgement_timeouts_; }

 private:
  struct Key {
    std::int64_t time_ns;
    StreamId stream;
    bool operator<(const Key& o) const {
      return std::tie(time_ns, stream) < std::tie(o.time_ns, o.stream);
    }
    bool operator==(const Key& o) const { return time_ns == o.time_ns && stream == o.stream; }
  };
  struct State {
    std::int64_t period_ns;
    bool sporadic{false};
    bool judging{false};
    bool judged_from_start{false};
    bool seen{false};
    bool active{true};
    std::int64_t last_time_ns{0};
    std::int64_t max_wait_ns{0};
    std::int64_t owed_up_to_ns{-1};    ///< judging: data handed to the judge up to here
    std::int64_t judged_up_to_ns{-1};  ///< judging: reported judged up to here
  };

  /// Sets aside the streams among `blocking` that held the head for their budget; true if
  /// none is left waiting.
  bool setAsideOverdue(std::int64_t waited_ns, const std::vector<StreamId>& blocking) {
    bool waiting = false;
    bool set_aside = false;
    for (const StreamId& id : blocking) {
      State& s = streams_.at(id);
      if (waited_ns < s.max_wait_ns) {
        waiting = true;
        continue;
      }
      s.active = false;
      if (s.judging)
        ++judgement_timeouts_;
      else
        set_aside = true;
    }
    if (set_aside) ++timeouts_;  // one bounded wait ran out (for one or more streams)
    return !waiting;
  }

  /// The expected, active streams that may still deliver a sample ordered before `key` (a
  /// buffer reused from call to call).
  const std::vector<StreamId>& blockingStreams(const Key& key) {
    blocking_.clear();
    for (const auto& [id, s] : streams_) {
      if (id == key.stream || !s.active) continue;
      if (s.judging && s.seen && s.owed_up_to_ns > s.judged_up_to_ns &&
          key.time_ns > s.judged_up_to_ns) {
        blocking_.push_back(id);
        continue;
      }
      if (s.sporadic) continue;
      const Key earliest_next{s.last_time_ns + s.period_ns, id};
      if (!s.seen || earliest_next < key) blocking_.push_back(id);
    }
    return blocking_;
  }

  /// Queues after every pending sample not ordered after `key` (equal keys: arrival order).
  void insertPending(const Key& key, Payload&& payload) {
    const std::size_t capacity = queue_.capacity();
    queue_.insert(pendingEnd(key), {key, std::move(payload)});
    if (queue_.capacity() != capacity) ++grown_;
  }

  /// Where a sample with `key` goes: after every pending one not ordered after it.
  typename std::vector<std::pair<Key, Payload>>::iterator pendingEnd(const Key& key) {
    return std::upper_bound(queue_.begin() + static_cast<std::ptrdiff_t>(head_), queue_.end(), key,
                            [](const Key& k, const auto& e) { return k < e.first; });
  }

  /// Drops the released samples from the front once they are half the buffer (moves, no
  /// allocation: the buffer keeps its capacity, so the steady state allocates nothing).
  void compact() {
    if (head_ == queue_.size()) {
      queue_.clear();
      head_ = 0;
    } else if (head_ > 64 && 2 * head_ > queue_.size()) {
      queue_.erase(queue_.begin(), queue_.begin() + static_cast<std::ptrdiff_t>(head_));
      head_ = 0;
    }
  }

  std::map<StreamId, State> streams_;
  /// Pending samples in release order from head_ (those before it are released), equal keys
  /// in arrival order.
  std::vector<std::pair<Key, Payload>> queue_;
  std::size_t head_{0};
  std::vector<StreamId> blocking_;
  Key last_released_{0, {}};
  bool released_any_{false};
  std::int64_t head_blocked_since_ns_{-1};
  Key blocked_key_{0, {}};
  std::uint64_t timeouts_{0};
  std::uint64_t grown_{0};
  std::uint64_t judgement_timeouts_{0};
};

}  // namespace navbus::nav_filter
