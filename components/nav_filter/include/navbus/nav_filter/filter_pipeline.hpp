// navbus-filter's processing without DDS: validate each sample (bus::StreamGate), merge the
// streams in time order (InputSequencer), run the navigation engine (components/core), and
// build the solution and diagnostics messages. The participant (filter_node.hpp) feeds it from
// DataReaders and writes what it emits; the offline runner (`navbus offline`) feeds it from
// the simulator directly, so both run the very same code on the same samples.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include <navbus_idl/Fault.h>
#include <navbus_idl/Gnss.h>
#include <navbus_idl/Imu.h>
#include <navbus_idl/Navigation.h>
#include <navbus_idl/StarTracker.h>

#include "navbus/bus/health.hpp"
#include "navbus/bus/streams.hpp"
#include "navbus/bus/validation.hpp"
#include "navbus/core/engine/navigation_engine.hpp"
#include "navbus/core/ins/output_predictor.hpp"
#include "navbus/nav_filter/command_gate.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/held_samples.hpp"
#include "navbus/nav_filter/input_history.hpp"
#include "navbus/nav_filter/input_sequencer.hpp"
#include "navbus/nav_filter/judgement_tracker.hpp"
#include "navbus/nav_filter/pipeline_summary.hpp"
#include "navbus/nav_filter/solution_flags.hpp"

namespace navbus::nav_filter {

/// The sensor streams' places in the ordered merge at equal data times (bus/streams.hpp).
inline constexpr int kRankImu = bus::streamInfo(bus::StreamKind::kImu).merge_rank;
inline constexpr int kRankGnssObs = bus::streamInfo(bus::StreamKind::kGnssObservations).merge_rank;
inline constexpr int kRankGnssFix = bus::streamInfo(bus::StreamKind::kGnssFix).merge_rank;
inline constexpr int kRankStarTracker = bus::streamInfo(bus::StreamKind::kStarTracker).merge_rank;
/// A command follows the measurements of its data time (the epoch its decision was taken at)
/// in the ordered merge.
inline constexpr int kRankCommand = 4;
static_assert(kRankCommand > kRankImu && kRankCommand > kRankGnssObs &&
                  kRankCommand > kRankGnssFix && kRankCommand > kRankStarTracker,
              "a command follows every measurement of its data time");
/// The commands' place in the merge (one stream, whoever issues them).
inline constexpr StreamId kCommandStream{kRankCommand, 0};
/// The fault manager's judgement of the IMU data itself (FaultMonitorProgress
/// imu_judged_up_to_gps_ns): a judging stream without samples (setImuJudged).
inline constexpr StreamId kImuJudgementStream{kRankCommand, 1};
/// The fault manager's judgement of the receivers' epochs (FaultMonitorProgress
/// gnss_judged_up_to_gps_ns, fault_monitor.receivers_judged): a judging stream without samples.
inline constexpr StreamId kGnssJudgementStream{kRankCommand, 2};

/// A validated GNSS observation epoch: satellite clock corrections applied.
struct GnssEpochInput {
  std::int64_t time_ns{0};
  std::vector<core::SatelliteObservation> satellites;
};

/// A command to the engine, at its data time (FilterCommand::time_gps_ns).
struct CommandInput {
  std::int64_t time_ns{0};
  navbus::FilterCommand command;
  /// Processed again after a rewind: it was checked when it first came, and applies as then.
  bool reapply{false};
};

using FilterInput = std::variant<core::ImuIncrement, GnssEpochInput, core::GnssFixMeasurement,
                                 core::StarAttitudeMeasurement, CommandInput>;

/// An input as the ordered merge released it: kept in the history, so that it can be merged
/// again in its place (InputSequencer::rewind).
struct MergedInput {
  StreamId stream;
  std::int64_t time_ns;
  FilterInput input;
};

/// The merge key of a command applied where the filter was restored to (before the onset of
/// the fault it answers): first among the inputs of its time.
inline constexpr StreamId kRestoredCommandStream{-1, 0};

class FilterPipeline {
 public:
  struct Sinks {
    std::function<void(const navbus::NavigationSolution&)> solution;
    std::function<void(const navbus::FilterDiagnostics&)> diagnostics;  ///< may be empty
    /// The low-latency output (FilterConfig::low_latency_output): one per IMU increment as it
    /// arrives, before the ordered merge; may be empty.
    std::function<void(const navbus::NavigationSolution&)> low_latency{};
    /// The answer to each command addressed to this filter (CommandGate); may be empty.
    std::function<void(const navbus::FilterCommandOutcome&)> command_outcome{};
  };

  FilterPipeline(const FilterConfig& config, bus::HealthCounters& health, Sinks sinks);
  /// A lane of a redundant set (LaneSet): its IMU's streams are counted in `imu_health` (the
  /// participant's, where every unit's counts go under its id), the streams every lane is fed
  /// (receivers, star tracker, commands) in `health` (the first lane's are the participant's).
  FilterPipeline(const FilterConfig& config, bus::HealthCounters& health,
                 bus::HealthCounters& imu_health, Sinks sinks);

  void onImu(const navbus::ImuIncrement& msg);
  /// A block of increments (fast pacing): its structure and block sequence are checked under
  /// the block topic, then every element goes through onImu as one increment sample (received,
  /// validated and counted under the increment topic), in order.
  void onImuBlock(const navbus::ImuIncrementBlock& msg);
  void onGnssObservations(const navbus::GnssObservationEpoch& msg);
  void onGnssFix(const navbus::GnssFix& msg);
  void onStarTracker(const navbus::StarTrackerAttitude& msg);
  /// Blocks of epochs, fixes and attitudes (fast pacing): as onImuBlock, each element through
  /// onGnssObservations, onGnssFix or onStarTracker as one sample of its own topic.
  void onGnssObservationsBlock(const navbus::GnssObservationEpochBlock& msg);
  void onGnssFixBlock(const navbus::GnssFixBlock& msg);
  void onStarTrackerBlock(const navbus::StarTrackerAttitudeBlock& msg);
  /// The writer of a stream announced the end of its data (disposed the instance): the stream
  /// no longer holds the ordered merge back, so what it preceded is released at once rather
  /// than after the bounded wait. Offline, flush() is the same end. Logged (streams in use).
  void onStreamEnded(bus::StreamKind kind, std::uint32_t id);
  /// Decisions are facts: counted and logged, never acted on (commands are).
  void onDecision(const navbus::FaultDecision& d);
  /// A command: stream commands act at once; engine commands enter the deterministic order at
  /// their data time (a sporadic stream: they never hold the merge up). A command whose time
  /// has already been passed is late: it acts at once, and one that answers a fault with an
  /// estimated onset restores the filter to before the onset and re-processes what followed
  /// (input_history.hpp), so the state afterwards is the same as if it had come in time. A
  /// refused one (wrong field, not available in this mode) is logged and counted.
  /// A command about data before the first input this run processed (or arriving before any,
  /// with a data time) is stale: the durable history of an earlier run, about data and a state
  /// this run never had. It is refused and counted, never re-applied.
  /// `writer_identity`: under DDS Security, the certificate common name of the participant
  /// that wrote the command (empty: unknown); nullopt where nobody is authenticated.
  void onCommand(const navbus::FilterCommand& c,
                 const std::optional<std::string>& writer_identity = std::nullopt);

  /// Processes every input that can no longer be preceded by another; `now_ns` is the clock
  /// that bounds the wait for a silent stream (steady time on the bus, data time offline).
  void pump(std::int64_t now_ns);
  /// The participant was not running for `stalled_ns` until `now_ns` (stopped, starved of
  /// CPU): the bounded wait for a silent stream starts again, since nothing could arrive
  /// meanwhile. Logged and counted.
  void resumedAfterStall(std::int64_t now_ns, std::int64_t stalled_ns);
  /// Whether any writer of the stream is alive (DDS liveliness). An IMU stream declared lost
  /// (CMD_EXCLUDE_STREAM) while its writer lives only flags the solutions: the merge keeps
  /// waiting for its increments, which a stalled or starved process between them delays but
  /// does not lose. Once no writer has lived for `sequencer_max_wait_s` of running time (this
  /// process's own stall, after which its liveliness view is stale, restarts the count), the
  /// filter goes on without it. Without this information (offline) a declaration acts at once.
  void setWritersAlive(bus::StreamKind kind, bool alive, std::int64_t now_ns);
  /// End of input (offline): releases everything still held, as the bounded wait would on
  /// the bus once every stream has fallen silent, and closes the engine's smoothing log (when
  /// its configuration has one).
  void flush(std::int64_t now_ns);
  /// While inertial data is lost, the last solution is republished (held, not propagated).
  void publishHeldSolution();

  /// How far the fault manager has judged the diagnostics. Once it reports, the ordered merge
  /// holds what follows each diagnostics epoch until that epoch is judged (within
  /// FaultMonitorWatch::judgement_wait_ns), so that a command answering it acts where offline
  /// it does, before the next solution is published.
  void onFaultMonitorProgress(const navbus::FaultMonitorProgress& report);
  /// A command of the lanes themselves (the least-squares lane's re-learn where its combination
  /// changed, lane_set.hpp): no issuer to authorize; it enters the deterministic order at its
  /// data time as any engine command.
  void addOwnCommand(const navbus::FilterCommand& c);
  /// A command given to another lane (lane_set.hpp): not this filter's to apply, but a report
  /// naming it may count now (a judgement waits for every command it names).
  void onCommandElsewhere(const navbus::FilterCommand& c) {
    if (const auto judged = judgements_.onCommand(c)) noteJudged(*judged);
  }
  /// A command the lanes apply themselves (CMD_SUSPECT_SENSOR_AXIS): this lane's judgement
  /// bookkeeping as for any command; true when it is this vehicle's and its issuer is
  /// authorized (a refusal is answered and counted here).
  bool admitLanesCommand(const navbus::FilterCommand& c,
                         const std::optional<std::string>& writer_identity) {
    onCommandElsewhere(c);
    return commands_.addressedToThisVehicle(c) && commands_.authorized(c, writer_identity);
  }
  /// The answer to such a command, as this filter's.
  void answerLanesCommand(const navbus::FilterCommand& c, bool applied, navbus::RejectReason reason,
                          const std::string& detail) {
    commands_.report(c, applied, reason, detail);
  }
  /// Whether a fault monitor is alive (the participant watches its reports): while not,
  /// solutions carry FAULT_NO_FAULT_MONITOR. Changes are logged and counted. (The wait for
  /// its judgement does not follow this: a monitor stopped for longer than its health timeout
  /// but within judgement_wait_ns is still waited for; a dead one costs one budget.)
  void setFaultMonitorAlive(bool alive) { flags_.setFaultMonitorAlive(alive); }
  /// A fault monitor judges this filter's IMU data (the parity test of redundant IMUs, whose
  /// reports then give how far it is judged): every increment processed is owed a judgement,
  /// so that a command about it acts where offline it does (lane_set.hpp).
  void setImuJudged() { owe_imu_judgement_ = true; }
  /// Some stream is currently lost, no fault monitor is alive, or the filter does not trust
  /// its own covariance (the participant reports DEGRADED).
  bool degraded() const { return flags_.degraded() || !engine_.trustworthy(); }
  /// New runs started because the IMU source restarted at an earlier time.
  std::uint64_t newRuns() const { return counters_.new_runs; }
  const core::NavigationEngine& engine() const { return engine_; }
  std::string summary() const;

 private:
  template <class Sample>
  bool admit(bus::StreamGate& gate, const Sample& msg, StreamId id,
             const std::optional<InputConfig>& expected);
  /// admit(), keeping a refused forward-jump candidate in `held`; on admission, `use` takes
  /// the held samples the admitted one confirmed, oldest first (HeldSamples).
  template <class Sample, class Use>
  bool admitOrHold(bus::StreamGate& gate, HeldSamples<Sample>& held, const Sample& msg, StreamId id,
                   const std::optional<InputConfig>& expected, Use use);
  /// A measurement block's structure and block sequence under `block_gate`; then each element,
  /// received under `element_gate`'s topic, to `take`.
  template <class Block, class Take>
  void takeBlock(const Block& msg, bus::StreamGate& block_gate, bus::StreamGate& element_gate,
                 Take take);
  /// After admission: convert to the core types, correct the configured time offset, queue.
  void useImu(const navbus::ImuIncrement& msg);
  void useGnssObservations(const navbus::GnssObservationEpoch& m);
  void useGnssFix(const navbus::GnssFix& m);
  void useStarTracker(const navbus::StarTrackerAttitude& m);
  void queue(bus::StreamGate& gate, StreamId id, std::int64_t time_ns, FilterInput input);
  /// A pseudorange epoch's satellite list: one the recovery history has forgotten (its storage
  /// kept, keepSatelliteList), else a new one. In the steady state the epochs allocate nothing.
  std::vector<core::SatelliteObservation> spareSatelliteList();
  /// Keeps the satellite list of the input the history is about to overwrite, for a next epoch.
  void keepSatelliteList(MergedInput* overwritten);
  void process(StreamId stream, std::int64_t time_ns, FilterInput&& owned);
  /// The fused receiver index of a receiver id (0: gnss_observations.id, 1: second_id).
  int receiverIndex(std::uint32_t receiver_id) const;
  /// Every fused receiver's observation stream has ended.
  bool fusedReceiverEnded() const;
  /// Fuses the receivers' epochs the engine holds as one (several fused receivers).
  void fuseHeldEpoch();
  /// A fused epoch's diagnostics out, each epoch time once (not while replaying).
  void diagnoseEpoch(std::int64_t time_ns);
  /// A sample whose place in the order was already passed: the engine is restored to before
  /// it (input history) and what followed is merged again with it. False beyond the history.
  bool mergeLate(StreamId id, std::int64_t time_ns, FilterInput& input);
  /// Counts a restore to before a fault's onset (or one the history could not reach).
  bool countRecovery(bool restored);
  /// After a rollback for `c`: re-processes up to its restore point, applies it there and
  /// re-processes the rest.
  bool applyFromRestorePoint(const navbus::FilterCommand& c);
  bool applyToEngine(const navbus::FilterCommand& c);
  /// An engine command into the merge at its data time (late: by rewinding, or at once).
  void enterCommand(const navbus::FilterCommand& c);
  void executeCommand(const navbus::FilterCommand& c);
  /// The IMU source restarted at an earlier time (a restarted simulator replaying its
  /// scenario): what is held of the old run is processed, then the filter starts over as at
  /// construction (engine, order, history, the other streams' time checks), so that the new
  /// run's inputs are used rather than rejected as not monotonic. Solution and diagnostics
  /// sequence numbers restart with it, which tells subscribers the same.
  void startNewRun();
  void publishSolution();
  /// Whether the solution about to be published is under a fault monitor's watch. Once the
  /// fault manager reports its progress, that is a fact of the data: the latest diagnostics
  /// epoch before the solution has been judged (the deterministic output waits for it, so
  /// only a judgement that ran out of its budget makes it false), and the bus and offline
  /// agree however the processes were scheduled. Before any report: the participant's view.
  bool monitored() const;
  void noteJudged(std::int64_t judged_up_to_ns);
  void publishDiagnostics();
  bool owe_imu_judgement_{false};
  /// fault_monitor.receivers_judged: each epoch's successor waits for the receivers' judgement.
  bool receivers_judged_{false};
  static constexpr std::size_t kSpareSatelliteLists = 4;
  std::vector<std::vector<core::SatelliteObservation>> spare_satellite_lists_;
  std::int64_t gnss_judged_passed_ns_{0};  ///< the receivers' judgement handed to the merge
  /// Propagates the low-latency output with an arrived increment and publishes it.
  void publishLowLatency(const core::ImuIncrement& inc);
  bool applyStreamCommand(const navbus::FilterCommand& c);
  /// The merge stops waiting for the IMU and the engine holds its last solution.
  void setImuLost();
  /// Why a stream-lost command does not hold here (the stream ended as announced), if so.
  std::optional<std::string> endedAsAnnounced(const navbus::FilterCommand& c) const;
  /// Applies a declared IMU loss once its writers have been gone long enough.
  void checkImuWriters(std::int64_t now_ns);

  FilterConfig config_;
  Sinks sinks_;
  InputSequencer<FilterInput> sequencer_;
  InputHistory<MergedInput> history_;
  std::deque<MergedInput> replay_;
  bool replaying_{false};
  core::NavigationEngine engine_;
  core::OutputPredictor predictor_;
  navbus::NavigationSolution anchor_solution_;  ///< the low-latency output's anchor, as published
  std::uint64_t low_latency_seq_{0};
  bus::TimeReference
      time_reference_;  ///< latest data time accepted on any input (before the gates)
  bus::StreamGate imu_gate_;
  bus::StreamGate imu_block_gate_;     ///< the block topic: structure and block sequence
  bus::StreamCounters& imu_counters_;  ///< health of the increment topic (received per element)
  bus::StreamGate gnss_obs_gate_;
  bus::StreamGate gnss_fix_gate_;
  bus::StreamGate star_gate_;
  bus::StreamGate gnss_obs_block_gate_;  ///< the block topics: structure and block sequence
  bus::StreamGate gnss_fix_block_gate_;
  bus::StreamGate star_block_gate_;
  HeldSamples<navbus::ImuIncrement> imu_held_;
  HeldSamples<navbus::GnssObservationEpoch> gnss_obs_held_;
  HeldSamples<navbus::GnssFix> gnss_fix_held_;
  HeldSamples<navbus::StarTrackerAttitude> star_held_;
  SolutionFlags flags_;  ///< stream-lost and fault-monitor flags of the solutions
  /// Merged streams whose writer announced their end (disposed), no sample since: not lost.
  std::set<StreamId> ended_streams_;
  std::uint64_t solution_seq_{0};
  std::uint64_t diagnostics_seq_{0};
  std::int64_t first_input_ns_{-1};  ///< data time of the first input processed (-1: none yet)
  CommandGate commands_;             ///< who may command what; the command counters
  JudgementTracker judgements_;      ///< the fault manager's progress reports
  std::int64_t last_pump_ns_{0};     ///< the clock of the latest pump
  PipelineCounters counters_;
  /// Since when no IMU writer lives [steady ns], or one of these.
  static constexpr std::int64_t kWritersUnknown = -1, kWritersAlive = -2;
  std::int64_t imu_writers_since_ns_{kWritersUnknown};
  /// Data time of the latest solution and diagnostics published: what is processed again
  /// after a rewind is not published twice.
  std::int64_t published_up_to_ns_{-1};
  std::int64_t diagnosed_up_to_ns_{-1};
  /// The data time of the latest diagnostics published, the state's (a GNSS epoch between two
  /// IMU increments is diagnosed at the increment before it): what the monitor must judge.
  std::int64_t owed_judgement_ns_{-1};
  std::int64_t judged_up_to_ns_{-1};  ///< the fault manager's judgement counted up to here
};

}  // namespace navbus::nav_filter
