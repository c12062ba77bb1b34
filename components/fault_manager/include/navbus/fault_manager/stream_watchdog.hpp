// Stream watchdog state machine: one state per (stream, sensor id). DDS supplies the timing
// (a requested deadline missed, a writer's liveliness lost); this class decides when a stream
// is lost and when it is back, once per transition. Pure logic, unit-tested.
//
// Wall-clock patience is for real-time streams only. A stream whose data time has run ahead
// of this participant's clock (a simulator in fast pacing, `navbus replay` faster than real
// time) is written as fast as its readers take it: its writer pauses whenever a reliable
// reader falls behind (a stopped filter), so its silences say nothing about the sensor. Such a
// stream is judged by its writer alone: an announced end, or liveliness lost. So is a stream
// that comes in blocks (ImuIncrementBlock and the others, Imu.idl): blocks exist for writing
// faster than real time, and it is known so from its first block, before its data time has run
// ahead (a replay starved of CPU from its start stays near real time for a while). And so is
// every stream of the same writing participant as a stream known paced so (a replay or a
// simulator paces all its streams together: its GNSS fixes wait with its increments).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <tuple>
#include <vector>

#include "navbus/bus/stream_kind.hpp"

namespace navbus::fault_manager {

/// Which stream (bus/streams.hpp has its topic, name and fault source).
using bus::StreamKind;

struct StreamKey {
  StreamKind kind;
  std::uint32_t sensor_id;
  bool operator<(const StreamKey& o) const {
    return std::tie(kind, sensor_id) < std::tie(o.kind, o.sensor_id);
  }
};

struct WatchdogEvent {
  StreamKey key;
  bool lost;  ///< true: stream lost; false: stream restored
  std::uint64_t
      last_time_gps_ns;  ///< sensor time of the latest sample seen (lost) or the new one (restored)
  double silence_s;      ///< wall time without data when the transition was decided
};

class StreamWatchdog {
 public:
  /// How a sample came: alone, or as an element of a block (paced by its writer).
  enum class Delivery { kSample, kBlock };
  /// The participant that wrote a sample: its DDS writer's GUID prefix (all zeros: not known).
  using WriterParticipant = std::array<std::uint8_t, 12>;
  struct Source {
    Delivery delivery{Delivery::kSample};
    WriterParticipant participant{};
  };
  /// A sample arrived; returns a 'restored' event if the stream was lost.
  std::optional<WatchdogEvent> onSample(const StreamKey& key, std::uint64_t time_gps_ns,
                                        std::int64_t wall_now_ns, const Source& source);
  /// The same, from an unknown participant, alone.
  std::optional<WatchdogEvent> onSample(const StreamKey& key, std::uint64_t time_gps_ns,
                                        std::int64_t wall_now_ns);
  /// DDS reported a missed deadline for this stream's instance; returns a 'lost' event once.
  /// The silence is confirmed on this participant's own clock first: if the latest sample was
  /// handed over less than `deadline_ns` ago (DDS's timer runs from reception, ours from the
  /// hand-over, which a loaded machine delays), the stream is only suspect (counted as an
  /// unconfirmed deadline event); onTick() declares it once its own silence reaches the
  /// deadline, and a sample before that clears it.
  std::optional<WatchdogEvent> onDeadlineMissed(const StreamKey& key, std::int64_t wall_now_ns,
                                                std::int64_t deadline_ns = 0);
  /// Suspect streams whose own silence has reached their deadline: lost.
  std::vector<WatchdogEvent> onTick(std::int64_t wall_now_ns);
  /// Deadline events not confirmed at once by the participant's own clock.
  std::uint64_t unconfirmedDeadlines() const { return unconfirmed_; }
  /// Deadline events of streams paced ahead of real time (not a loss, see the file comment).
  std::uint64_t deadlinesAheadOfRealTime() const { return deadlines_ahead_; }
  /// Stream runs recognised as paced ahead of real time (by their data time, their blocks, or
  /// their writing participant's other streams).
  std::uint64_t streamsAheadOfRealTime() const { return streams_ahead_; }
  /// How far a stream's data time must run ahead of the wall clock, both counted from its
  /// first sample, before it counts as paced ahead of real time. A real-time stream cannot get
  /// there unless this participant was stopped for longer than this when the first sample came
  /// (its later samples would then look early by the length of that stop).
  static constexpr std::int64_t kAheadOfRealTimeNs = 2'000'000'000;
  /// Every writer of a topic lost liveliness: all its streams that are alive are lost; within
  /// kLivelinessGraceNs after a stall of this participant, only once the grace has passed
  /// without the writers alive again (onTick).
  std::vector<WatchdogEvent> onWritersGone(StreamKind kind, std::int64_t wall_now_ns);
  /// A writer of the topic is alive (again).
  void onWritersAlive(StreamKind kind);
  /// This participant was not running until `wall_now_ns` (bus::StallDetector): its view of
  /// its peers is stale. Silence counts again from now, and a writer's liveliness lost is
  /// believed only if it is not back within kLivelinessGraceNs.
  void resumedAfterStall(std::int64_t wall_now_ns);
  /// How long lost liveliness seen right after a stall waits for the writer to be heard:
  /// twice the sensor writers' 1 s lease (qos/navbus_qos.xml).
  static constexpr std::int64_t kLivelinessGraceNs = 2'000'000'000;
  /// Writers-gone events after a stall that the writers' liveliness then contradicted.
  std::uint64_t staleLivelinessEvents() const { return stale_liveliness_; }

  /// The stream's writer disposed it (an announced end) after data up to `end_time_gps_ns`
  /// (or its latest sample seen, if later): forgotten, so that its silence is no loss. Samples
  /// not later than the end still in flight (another reader of the same topic may deliver
  /// them after the dispose) are ignored; a later one starts the stream again. Returns false
  /// if the stream was not known (its end is kept all the same: this participant's other
  /// reader told it before this one's samples came). A sample from another writing
  /// participant than the ended run's is a new run whatever its time (a restarted source).
  bool onEnded(const StreamKey& key, std::uint64_t end_time_gps_ns = 0);
  /// The participant `writer` announced the end of all its data (its health, STATE_ENDED: a
  /// reliable report, where the watchdog's best-effort reader can lose a dispose). Returns the
  /// streams whose latest sample it wrote, for the caller to end (onEnded); its samples still in
  /// flight are ignored from now on (a new run of its sensor comes from a new participant).
  std::vector<StreamKey> onParticipantEnded(const WriterParticipant& writer);
  /// Sensor time of the stream's latest sample (0: not known).
  std::uint64_t lastTime(const StreamKey& key) const;

  bool isLost(const StreamKey& key) const;

 private:
  struct State {
    bool lost{false};
    std::uint64_t last_time_gps_ns{0};
    std::int64_t last_arrival_wall_ns{0};
    std::int64_t suspect_deadline_ns{-1};   ///< a DDS deadline event awaits confirmation (-1: no)
    std::uint64_t first_time_gps_ns{0};     ///< the run's first sample: sensor time
    std::int64_t first_arrival_wall_ns{0};  ///< ... and when it arrived
    bool ahead_of_real_time{false};         ///< once seen ahead, for the rest of the run
    WriterParticipant participant{};        ///< of the latest sample
  };
  /// The sample belongs to a run that ended as announced and was still in flight: not later
  /// than the stream's end and from the same participant (or one not known), or from a
  /// participant that announced the end of all its data.
  bool ofEndedRun(const StreamKey& key, std::uint64_t time_gps_ns, const Source& source) const;
  void notePace(State& s, const Source& source);
  /// The stream's data time has run ahead of the wall clock (kAheadOfRealTimeNs).
  static bool dataTimeAhead(const State& s);
  void markAhead(State& s);
  std::vector<WatchdogEvent> markKindLost(StreamKind kind, std::int64_t wall_now_ns);
  std::optional<WatchdogEvent> markLost(const StreamKey& key, State& s, std::int64_t wall_now_ns);
  std::map<StreamKey, State> states_;
  struct End {
    std::uint64_t time_gps_ns{0};     ///< data time of the stream's last sample
    WriterParticipant participant{};  ///< that wrote it (all zeros: not known)
  };
  std::map<StreamKey, End> ended_at_;  ///< announced ends
  std::uint64_t unconfirmed_{0};
  std::uint64_t deadlines_ahead_{0};
  std::int64_t grace_until_ns_{-1};          ///< after a stall: writers-gone events wait until here
  std::map<StreamKind, bool> gone_pending_;  ///< writers gone during the grace (kind -> pending)
  std::uint64_t stale_liveliness_{0};
  std::uint64_t streams_ahead_{0};
  std::set<WriterParticipant> paced_participants_;  ///< wrote a stream paced ahead
  std::set<WriterParticipant> ended_participants_;  ///< announced the end of all their data
};

}  // namespace navbus::fault_manager
