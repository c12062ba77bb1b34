// Per-input counters of a participant and their Health message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <string>

#include <navbus_idl/Health.h>

namespace navbus::bus {

/// Counters of one sensor id (an IMU unit, a GNSS receiver) on a topic that carries several.
struct SensorCounters {
  std::uint64_t accepted{0};
  std::uint64_t rejected{0};  ///< every reason
  std::uint64_t sequence_gaps{0};
  std::uint64_t source_restarts{0};
};

struct StreamCounters {
  /// How many sensor ids a stream counts one by one (the bound of StreamHealth::sensors in
  /// idl/Health.idl): what a source of ever new ids can make a participant hold and publish.
  static constexpr std::size_t kMaxSensors = 8;

  std::uint64_t received{0};
  std::uint64_t accepted{0};
  std::uint64_t sequence_gaps{0};
  std::uint64_t deadline_misses{0};
  std::uint64_t source_restarts{0};  ///< new runs of the source (SequenceTracker::Outcome)
  std::map<navbus::RejectReason, std::uint64_t> rejected;
  /// Elements dropped from accepted samples (satellites of an epoch), by reason.
  std::map<navbus::RejectReason, std::uint64_t> elements_rejected;
  /// Per sensor id, the first kMaxSensors ids seen.
  std::map<std::uint32_t, SensorCounters> sensors;
  /// Samples (accepted or rejected) of ids beyond the first kMaxSensors.
  std::uint64_t unlisted_sensor_samples{0};

  std::uint64_t rejectedTotal() const;
  /// The counters of `sensor_id`, made on its first sample while fewer than kMaxSensors ids
  /// are counted; nullptr beyond (the caller counts the sample in unlisted_sensor_samples).
  SensorCounters* sensor(std::uint32_t sensor_id);
  /// One sample of `sensor_id` accepted, `missing` samples of it before it by its sequence
  /// numbers: counted on the topic and under the id.
  void countAccepted(std::uint32_t sensor_id, std::uint64_t missing = 0);
};

/// Counters of every input topic, in registration order.
class HealthCounters {
 public:
  explicit HealthCounters(std::string participant) : participant_(std::move(participant)) {}

  /// Returns the counters of a topic, creating them on first use. The reference stays valid
  /// for the lifetime of this object.
  StreamCounters& stream(const std::string& topic);
  const StreamCounters* find(const std::string& topic) const;

  void countPublished(std::uint64_t n = 1) { published_ += n; }
  std::uint64_t published() const { return published_; }
  /// From the first input to the first processing state (Health::resume_ns) [ns].
  void setResumeNs(std::uint64_t ns) { resume_ns_ = ns; }

  /// Builds the next report (sequence incremented on each call).
  navbus::Health report(navbus::ParticipantState state, std::uint64_t wall_time_ns);
  /// The same into `into`, whose vectors and strings are reused: a participant that keeps one
  /// message allocates nothing for its reports once the set of streams and reasons is stable.
  void report(navbus::ParticipantState state, std::uint64_t wall_time_ns, navbus::Health& into);

  /// One line per stream, for the end-of-run summary.
  std::string summary() const;

 private:
  std::string participant_;
  std::deque<std::pair<std::string, StreamCounters>> streams_;  // deque: references stay valid
  std::uint64_t published_{0};
  std::uint64_t resume_ns_{0};
  std::uint64_t seq_{0};
};

const char* rejectReasonName(navbus::RejectReason reason);

}  // namespace navbus::bus
