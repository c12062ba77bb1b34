#include "navbus/bus/health.hpp"

#include <sstream>
#include <vector>

namespace navbus::bus {

std::uint64_t StreamCounters::rejectedTotal() const {
  std::uint64_t n = 0;
  for (const auto& [reason, count] : rejected) {
    n += count;
  }
  return n;
}

SensorCounters* StreamCounters::sensor(std::uint32_t sensor_id) {
  const auto it = sensors.find(sensor_id);
  if (it != sensors.end()) return &it->second;
  if (sensors.size() >= kMaxSensors) return nullptr;
  return &sensors[sensor_id];
}

void StreamCounters::countAccepted(std::uint32_t sensor_id, std::uint64_t missing) {
  ++accepted;
  sequence_gaps += missing;
  if (SensorCounters* s = sensor(sensor_id)) {
    ++s->accepted;
    s->sequence_gaps += missing;
  } else {
    ++unlisted_sensor_samples;
  }
}

StreamCounters& HealthCounters::stream(const std::string& topic) {
  for (auto& [name, counters] : streams_) {
    if (name == topic) {
      return counters;
    }
  }
  streams_.emplace_back(topic, StreamCounters{});
  return streams_.back().second;
}

const StreamCounters* HealthCounters::find(const std::string& topic) const {
  for (const auto& [name, counters] : streams_) {
    if (name == topic) {
      return &counters;
    }
  }
  return nullptr;
}

namespace {

/// Copies `counts` into `into`, reusing its elements (no allocation once it had as many).
template <class Counts>
void fillRejectCounts(const Counts& counts, std::vector<navbus::RejectCount>& into) {
  into.resize(counts.size());
  std::size_t i = 0;
  for (const auto& [reason, count] : counts) {
    into[i].reason(reason);
    into[i].count(count);
    ++i;
  }
}

void fillSensorCounts(const std::map<std::uint32_t, SensorCounters>& counts,
                      std::vector<navbus::SensorStreamHealth>& into) {
  into.resize(counts.size());
  std::size_t i = 0;
  for (const auto& [id, c] : counts) {
    navbus::SensorStreamHealth& s = into[i++];
    s.sensor_id(id);
    s.accepted(c.accepted);
    s.rejected(c.rejected);
    s.sequence_gaps(c.sequence_gaps);
    s.source_restarts(c.source_restarts);
  }
}

}  // namespace

void HealthCounters::report(navbus::ParticipantState state, std::uint64_t wall_time_ns,
                            navbus::Health& h) {
  h.participant(participant_);
  h.seq(++seq_);
  h.wall_time_ns(wall_time_ns);
  h.state(state);
  h.samples_published(published_);
  h.resume_ns(resume_ns_);
  h.inputs().resize(streams_.size());
  std::size_t i = 0;
  for (const auto& [name, c] : streams_) {
    navbus::StreamHealth& s = h.inputs()[i++];
    s.topic(name);  // assigned: the string keeps its storage
    s.received(c.received);
    s.accepted(c.accepted);
    s.sequence_gaps(c.sequence_gaps);
    s.deadline_misses(c.deadline_misses);
    s.source_restarts(c.source_restarts);
    fillRejectCounts(c.rejected, s.rejected());
    fillRejectCounts(c.elements_rejected, s.elements_rejected());
    fillSensorCounts(c.sensors, s.sensors());
    s.unlisted_sensor_samples(c.unlisted_sensor_samples);
  }
}

navbus::Health HealthCounters::report(navbus::ParticipantState state, std::uint64_t wall_time_ns) {
  navbus::Health h;
  report(state, wall_time_ns, h);
  return h;
}

std::string HealthCounters::summary() const {
  std::ostringstream out;
  for (const auto& [name, c] : streams_) {
    out << "  " << name << ": received " << c.received << ", accepted " << c.accepted
        << ", rejected " << c.rejectedTotal();
    for (const auto& [reason, count] : c.rejected) {
      out << " [" << rejectReasonName(reason) << " " << count << "]";
    }
    for (const auto& [reason, count] : c.elements_rejected) {
      out << " [element " << rejectReasonName(reason) << " " << count << "]";
    }
    out << ", sequence gaps " << c.sequence_gaps << ", deadline misses " << c.deadline_misses;
    if (c.source_restarts > 0) out << ", source restarts " << c.source_restarts;
    out << "\n";
    // One line per sensor when the topic carries several (the one sensor's are the topic's).
    if (c.sensors.size() > 1 || c.unlisted_sensor_samples > 0) {
      for (const auto& [id, s] : c.sensors) {
        out << "    sensor " << id << ": accepted " << s.accepted << ", rejected " << s.rejected
            << ", sequence gaps " << s.sequence_gaps;
        if (s.source_restarts > 0) out << ", source restarts " << s.source_restarts;
        out << "\n";
      }
      if (c.unlisted_sensor_samples > 0)
        out << "    further sensor ids (not counted one by one): " << c.unlisted_sensor_samples
            << " samples\n";
    }
  }
  out << "  published: " << published_ << " samples\n";
  return out.str();
}

const char* rejectReasonName(navbus::RejectReason reason) {
  switch (reason) {
    case navbus::REJECT_NOT_FINITE:
      return "not_finite";
    case navbus::REJECT_OUT_OF_RANGE:
      return "out_of_range";
    case navbus::REJECT_TIME_NOT_MONOTONIC:
      return "time_not_monotonic";
    case navbus::REJECT_DUPLICATE:
      return "duplicate";
    case navbus::REJECT_UNKNOWN_SATELLITE:
      return "unknown_satellite";
    case navbus::REJECT_BAD_INTERVAL:
      return "bad_interval";
    case navbus::REJECT_BAD_QUATERNION:
      return "bad_quaternion";
    case navbus::REJECT_LATE:
      return "late";
    case navbus::REJECT_UNEXPECTED_SOURCE:
      return "unexpected_source";
    case navbus::REJECT_INCONSISTENT:
      return "inconsistent";
    case navbus::REJECT_DUPLICATE_SATELLITE:
      return "duplicate_satellite";
    case navbus::REJECT_TIME_JUMP:
      return "time_jump";
    case navbus::REJECT_SECOND_WRITER:
      return "second_writer";
    case navbus::REJECT_UNAUTHORIZED:
      return "unauthorized";
    case navbus::REJECT_STALE:
      return "stale";
    case navbus::REJECT_NOT_APPLICABLE:
      return "not_applicable";
    case navbus::REJECT_MALFORMED:
      return "malformed";
    case navbus::REJECT_CLIENT_BEHIND:
      return "client_behind";
  }
  return "unknown";
}

}  // namespace navbus::bus
