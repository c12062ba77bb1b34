// navbus-fault-manager's processing without DDS, the shape of navbus-filter's FilterPipeline:
// stream events and the filter's diagnostics in; decisions (facts) and commands (requests)
// out through sinks. One detector per file beside it: stream_watchdog (silence), glr_detector
// (seed 000), dither_detector (seed 003, the raw IMU stream). The participant
// (fault_manager_node.hpp) owns the readers and writers and feeds it; `navbus offline` runs it in
// the same process as the filter pipeline.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include <navbus_idl/Fault.h>
#include <navbus_idl/Navigation.h>

#include "navbus/bus/health.hpp"
#include "navbus/bus/validation.hpp"
#include "navbus/fault_manager/command_outcomes.hpp"
#include "navbus/fault_manager/dither_detector.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/fault_output.hpp"
#include "navbus/fault_manager/glr_detector.hpp"
#include "navbus/fault_manager/parity_detector.hpp"
#include "navbus/fault_manager/receiver_detector.hpp"
#include "navbus/fault_manager/stream_watchdog.hpp"

namespace navbus::fault_manager {

class FaultPipeline : private FaultOutput {
 public:
  struct Sinks {
    std::function<void(const navbus::FaultDecision&)> decision;
    std::function<void(const navbus::FilterCommand&)> command;
    /// How far the filter's diagnostics are judged: after every epoch of this vehicle, after
    /// the epoch's commands (may be empty).
    std::function<void(const navbus::FaultMonitorProgress&)> progress{};
  };

  /// `run_id` goes into every decision and command (the run's start time on the bus, 0
  /// offline), so that ids are unique across restarts.
  FaultPipeline(const FaultManagerConfig& config, bus::HealthCounters& health, Sinks sinks,
                std::uint64_t run_id = 0);

  // Stream watchdogs (wall times from the participant's steady clock).
  /// A sample of a watched stream; `seq` counts samples a best-effort reader lost. `source`:
  /// alone or in a block, and its writing participant (how the watchdog tells a stream paced
  /// by its writer).
  void onStreamSample(StreamKind kind, std::uint32_t sensor_id, std::uint64_t seq,
                      std::uint64_t time_gps_ns, std::int64_t wall_now_ns,
                      const StreamWatchdog::Source& source = {});
  void onDeadlineMissed(StreamKind kind, std::uint32_t sensor_id, std::int64_t wall_now_ns);
  void onWritersGone(StreamKind kind, std::int64_t wall_now_ns);
  /// A writer of the stream kind is alive (again).
  void onWritersAlive(StreamKind kind) { watchdog_.onWritersAlive(kind); }
  /// This participant was not running for `stalled_ns` until `wall_now_ns`: the watchdog's
  /// view is stale (StreamWatchdog::resumedAfterStall). Logged and counted.
  void resumedAfterStall(std::int64_t wall_now_ns, std::int64_t stalled_ns);
  /// Periodic: declares suspect streams whose own silence reached the deadline.
  void onWatchdogTick(std::int64_t wall_now_ns);
  /// The stream's writer announced its end (disposed the instance): no loss, counted.
  void onStreamEnded(StreamKind kind, std::uint32_t sensor_id, std::uint64_t end_time_gps_ns = 0);
  /// A participant announced the end of all its data (its health report, STATE_ENDED): every
  /// stream it wrote ends as if its dispose had come, which a best-effort watchdog reader can
  /// lose. Returns the streams ended.
  std::vector<StreamKey> onWriterParticipantEnded(const StreamWatchdog::WriterParticipant& writer);
  /// A second writer publishes a stream's sensor id while its owner is alive (bus::WriterGate):
  /// a fault decision (detector "writer-identity"), once per intruding writer. No command: the
  /// filter keeps that writer's samples out by itself.
  void onSecondWriter(StreamKind kind, std::uint32_t sensor_id, std::uint64_t time_gps_ns);
  /// The watchdog deadline of a stream kind [s], quoted as the decisions' threshold.
  void setDeadline(StreamKind kind, double deadline_s) { deadline_s_[kind] = deadline_s; }

  /// The monitored filter's diagnostics (validated here; other vehicles are ignored). True
  /// when the GLR evaluated the epoch (its statistic is then glr().latest()). Every epoch of
  /// this vehicle, used or refused, is reported judged (Sinks::progress) once its commands
  /// are out.
  bool onDiagnostics(const navbus::FilterDiagnostics& msg);
  /// A raw IMU block, for the dither monitor (watchdog bookkeeping goes through
  /// onStreamSample as for every stream).
  void onRawBlock(const navbus::ImuRawBlock& block);
  /// A navigation-rate increment of any IMU unit, for the parity detector (every increment,
  /// a fast-pacing block's elements one by one).
  void onImuIncrement(const navbus::ImuIncrement& increment);
  /// A filter lane's solution (navbus/nav/lane_solution), for the parity detector: the lanes'
  /// naming of an ambiguous decision's faulty unit becomes a decision. Other vehicles ignored.
  void onLaneSolution(const navbus::LaneSolution& lane);
  /// A unit's increments ended as announced (the parity reader got its dispose after its last
  /// sample): once every unit has, the parity test's progress is reported to the end.
  void onParityUnitEnded(std::uint32_t sensor_id);

  const GlrDetector& glr() const { return glr_; }
  /// The dither detector, when configured.
  const std::optional<DitherDetector>& dither() const { return dither_; }
  /// An observation epoch of any GNSS receiver, for the cross-receiver detector (every epoch,
  /// reliably; none without `receivers:`).
  void onGnssEpoch(const navbus::GnssObservationEpoch& epoch);
  const std::optional<ReceiverDetector>& receivers() const { return receivers_; }
  /// The parity detector of redundant IMUs, when configured.
  const std::optional<ParityDetector>& parity() const { return parity_; }
  std::uint64_t decisions() const { return next_decision_id_ - 1; }
  std::uint64_t commands() const { return next_command_id_ - 1; }
  /// The filter's answer to a command (its own are counted; others ignored). A refusal or a
  /// clamp is logged, and the participant reports DEGRADED until a later command of this run
  /// is applied (degraded()).
  void onCommandOutcome(const navbus::FilterCommandOutcome& o);
  /// The loop is not closed: the latest command was refused or clamped by the filter.
  bool degraded() const { return outcomes_.degraded(); }
  std::string summary() const;

 private:
  std::uint32_t decide(navbus::FaultDecision& d) override;
  void command(navbus::FilterCommand& c) override;
  void satelliteKeptOut(int sv_id) override;
  void onWatchdogEvent(const WatchdogEvent& e);
  void reportProgress(const navbus::FilterDiagnostics& judged);
  /// A progress report when the cross-receiver test has judged further.
  void reportReceiversProgress();
  /// A receiver's stream ended or was declared lost after its sample at `last_time_gps_ns`: the
  /// cross-receiver test stops waiting for it beyond that time (other stream kinds: nothing).
  void receiverGone(StreamKind kind, std::uint32_t sensor_id, std::uint64_t last_time_gps_ns);

  FaultManagerConfig config_;
  bus::HealthCounters& health_;
  Sinks sinks_;
  StreamWatchdog watchdog_;
  GlrDetector glr_;
  std::optional<DitherDetector> dither_;
  std::optional<ParityDetector> parity_;
  std::optional<ReceiverDetector> receivers_;
  /// The parity test's progress is reported every this much data time.
  static constexpr std::int64_t kParityReportPeriodNs = 100'000'000;
  std::int64_t parity_reported_{-1};     ///< data time of the latest report of it
  std::uint64_t parity_runs_{0};         ///< the parity test's new runs seen
  std::int64_t receivers_reported_{-1};  ///< the cross-receiver test's latest reported time
  navbus::FilterDiagnostics judged_;     ///< the latest diagnostics epoch judged (reports quote it)
  bus::StreamGate diagnostics_gate_;
  std::map<StreamKind, bus::SequenceTracker> trackers_;
  std::map<StreamKind, double> deadline_s_;
  std::uint64_t second_writers_{0};
  std::uint64_t stalls_{0};  ///< pauses of this participant's process
  std::int64_t longest_stall_ns_{0};
  std::uint64_t filter_new_runs_{0};  ///< the diagnostics' source restarted at an earlier time
  std::uint64_t run_id_{0};
  CommandOutcomes outcomes_;
  std::uint32_t next_decision_id_{1};
  std::uint64_t next_command_id_{1};
  std::uint64_t lost_{0}, restored_{0}, ended_{0}, other_vehicles_{0};
};

}  // namespace navbus::fault_manager
