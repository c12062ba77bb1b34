#include "navbus/fault_manager/stream_watchdog.hpp"

#include <algorithm>

namespace navbus::fault_manager {

std::optional<WatchdogEvent> StreamWatchdog::onSample(const StreamKey& key,
                                                      std::uint64_t time_gps_ns,
                                                      std::int64_t wall_now_ns) {
  return onSample(key, time_gps_ns, wall_now_ns, Source{});
}

std::optional<WatchdogEvent> StreamWatchdog::onSample(const StreamKey& key,
                                                      std::uint64_t time_gps_ns,
                                                      std::int64_t wall_now_ns,
                                                      const Source& source) {
  if (ofEndedRun(key, time_gps_ns, source)) return std::nullopt;
  ended_at_.erase(key);  // a new run of the stream, if it had ended
  auto [it, inserted] = states_.try_emplace(key);
  State& s = it->second;
  std::optional<WatchdogEvent> event;
  if (!inserted && s.lost) {
    event = WatchdogEvent{key, false, time_gps_ns,
                          1e-9 * static_cast<double>(wall_now_ns - s.last_arrival_wall_ns)};
  }
  if (inserted) {
    s.first_time_gps_ns = time_gps_ns;
    s.first_arrival_wall_ns = wall_now_ns;
  }
  s.lost = false;
  s.suspect_deadline_ns = -1;
  s.last_time_gps_ns = time_gps_ns;
  s.last_arrival_wall_ns = wall_now_ns;
  s.participant = source.participant;
  notePace(s, source);
  return event;
}

bool StreamWatchdog::ofEndedRun(const StreamKey& key, std::uint64_t time_gps_ns,
                                const Source& source) const {
  if (ended_participants_.count(source.participant) > 0) return true;
  const auto ended = ended_at_.find(key);
  if (ended == ended_at_.end()) return false;
  const WriterParticipant& wrote = ended->second.participant;
  const bool other_writer = source.participant != WriterParticipant{} &&
                            wrote != WriterParticipant{} && source.participant != wrote;
  return !other_writer && time_gps_ns <= ended->second.time_gps_ns;
}

void StreamWatchdog::notePace(State& s, const Source& source) {
  const bool known = source.participant != WriterParticipant{};
  if (!s.ahead_of_real_time && (source.delivery == Delivery::kBlock || dataTimeAhead(s) ||
                                (known && paced_participants_.count(source.participant) > 0)))
    markAhead(s);
  if (!s.ahead_of_real_time || !known || !paced_participants_.insert(source.participant).second)
    return;
  for (auto& [key, other] : states_) {  // its writer's other streams, seen before this one
    if (other.participant == source.participant) markAhead(other);
  }
}

bool StreamWatchdog::dataTimeAhead(const State& s) {
  if (s.last_time_gps_ns < s.first_time_gps_ns) return false;
  const auto data_span_ns = static_cast<std::int64_t>(s.last_time_gps_ns - s.first_time_gps_ns);
  const std::int64_t wall_span_ns = s.last_arrival_wall_ns - s.first_arrival_wall_ns;
  return data_span_ns - wall_span_ns > kAheadOfRealTimeNs;
}

void StreamWatchdog::markAhead(State& s) {
  if (s.ahead_of_real_time) return;
  s.ahead_of_real_time = true;
  s.suspect_deadline_ns = -1;  // a silence it was suspected of says nothing now
  ++streams_ahead_;
}

std::optional<WatchdogEvent> StreamWatchdog::markLost(const StreamKey& key, State& s,
                                                      std::int64_t wall_now_ns) {
  if (s.lost) return std::nullopt;
  s.lost = true;
  s.suspect_deadline_ns = -1;
  return WatchdogEvent{key, true, s.last_time_gps_ns,
                       1e-9 * static_cast<double>(wall_now_ns - s.last_arrival_wall_ns)};
}

std::optional<WatchdogEvent> StreamWatchdog::onDeadlineMissed(const StreamKey& key,
                                                              std::int64_t wall_now_ns,
                                                              std::int64_t deadline_ns) {
  auto it = states_.find(key);
  // A stream never seen cannot be lost: the deadline only counts for instances that exist.
  if (it == states_.end()) return std::nullopt;
  State& st = it->second;
  if (st.ahead_of_real_time) {
    ++deadlines_ahead_;
    return std::nullopt;
  }
  if (!st.lost && wall_now_ns - st.last_arrival_wall_ns < deadline_ns) {
    ++unconfirmed_;
    st.suspect_deadline_ns = deadline_ns;
    return std::nullopt;
  }
  return markLost(key, st, wall_now_ns);
}

std::vector<WatchdogEvent> StreamWatchdog::onTick(std::int64_t wall_now_ns) {
  std::vector<WatchdogEvent> out;
  if (wall_now_ns >= grace_until_ns_) {
    for (auto& [kind, pending] : gone_pending_) {
      if (!pending) continue;
      pending = false;
      for (const auto& e : markKindLost(kind, wall_now_ns)) out.push_back(e);
    }
  }
  for (auto& [key, s] : states_) {
    if (s.suspect_deadline_ns < 0 || wall_now_ns - s.last_arrival_wall_ns < s.suspect_deadline_ns)
      continue;
    if (auto e = markLost(key, s, wall_now_ns)) out.push_back(*e);
  }
  return out;
}

std::vector<WatchdogEvent> StreamWatchdog::onWritersGone(StreamKind kind,
                                                         std::int64_t wall_now_ns) {
  if (wall_now_ns < grace_until_ns_) {
    gone_pending_[kind] = true;  // perhaps only this participant's stale view: wait and see
    return {};
  }
  return markKindLost(kind, wall_now_ns);
}

void StreamWatchdog::onWritersAlive(StreamKind kind) {
  auto it = gone_pending_.find(kind);
  if (it == gone_pending_.end() || !it->second) return;
  it->second = false;
  ++stale_liveliness_;
}

void StreamWatchdog::resumedAfterStall(std::int64_t wall_now_ns) {
  grace_until_ns_ = wall_now_ns + kLivelinessGraceNs;
  for (auto& [key, s] : states_) {
    s.last_arrival_wall_ns = std::max(s.last_arrival_wall_ns, wall_now_ns);
    s.suspect_deadline_ns = -1;
  }
}

std::vector<WatchdogEvent> StreamWatchdog::markKindLost(StreamKind kind, std::int64_t wall_now_ns) {
  std::vector<WatchdogEvent> out;
  for (auto& [key, s] : states_) {
    if (key.kind != kind) continue;
    if (auto e = markLost(key, s, wall_now_ns)) out.push_back(*e);
  }
  return out;
}

bool StreamWatchdog::onEnded(const StreamKey& key, std::uint64_t end_time_gps_ns) {
  const auto it = states_.find(key);
  const bool known = it != states_.end();
  // Kept for a stream not seen yet too: another reader of the participant told the end, and
  // this one's samples up to it are still to come.
  End& ended = ended_at_[key];
  ended.time_gps_ns =
      std::max({ended.time_gps_ns, end_time_gps_ns, known ? it->second.last_time_gps_ns : 0});
  if (known) {
    ended.participant = it->second.participant;
    states_.erase(it);
  }
  return known;
}

std::vector<StreamKey> StreamWatchdog::onParticipantEnded(const WriterParticipant& writer) {
  std::vector<StreamKey> keys;
  if (writer == WriterParticipant{}) return keys;  // not known: names no stream
  ended_participants_.insert(writer);
  for (const auto& [key, s] : states_) {
    if (s.participant == writer) keys.push_back(key);
  }
  return keys;
}

std::uint64_t StreamWatchdog::lastTime(const StreamKey& key) const {
  const auto it = states_.find(key);
  return it == states_.end() ? 0 : it->second.last_time_gps_ns;
}

bool StreamWatchdog::isLost(const StreamKey& key) const {
  auto it = states_.find(key);
  return it != states_.end() && it->second.lost;
}

}  // namespace navbus::fault_manager
