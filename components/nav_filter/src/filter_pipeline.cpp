#include "navbus/nav_filter/filter_pipeline.hpp"

#include <algorithm>
#include <array>

#include <cmath>
#include <type_traits>

#include <spdlog/spdlog.h>

#include "navbus/bus/conversions.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/bus/streams.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/nav_filter/pipeline_summary.hpp"
#include "navbus/nav_filter/solution_messages.hpp"

namespace navbus::nav_filter {

namespace {

std::vector<InputSequencer<FilterInput>::ExpectedStream> expectedStreams(const FilterConfig& c) {
  std::vector<InputSequencer<FilterInput>::ExpectedStream> s;
  s.push_back({{kRankImu, c.imu.id}, c.imu.period_ns, false, false, c.imu.max_wait_ns});
  if (c.gnss_observations)
    s.push_back({{kRankGnssObs, c.gnss_observations->id}, c.gnss_observations->period_ns});
  if (c.second_gnss_receiver_id)
    s.push_back({{kRankGnssObs, *c.second_gnss_receiver_id}, c.gnss_observations->period_ns});
  if (c.gnss_fix) s.push_back({{kRankGnssFix, c.gnss_fix->id}, c.gnss_fix->period_ns});
  if (c.star_tracker)
    s.push_back({{kRankStarTracker, c.star_tracker->id}, c.star_tracker->period_ns});
  // The fault manager's commands: sporadic, and held for where a judgement is owed.
  const bool monitored = c.fault_monitor.has_value();
  s.push_back({kCommandStream, 0, true, monitored,
               monitored ? c.fault_monitor->judgement_wait_ns : 0,
               monitored && c.fault_monitor->judged_from_start});
  // The judgement of the IMU data itself (the parity test of redundant IMUs): carries no
  // samples, holds the merge where owed once its judge has reported (setImuJudged).
  if (monitored)
    s.push_back({kImuJudgementStream, 0, true, true, c.fault_monitor->judgement_wait_ns,
                 c.fault_monitor->judged_from_start});
  // The judgement of the receivers' epochs (the cross-receiver test), expected from the start.
  if (monitored && c.fault_monitor->receivers_judged)
    s.push_back({kGnssJudgementStream, 0, true, true, c.fault_monitor->judgement_wait_ns, true});
  return s;
}

/// Inputs per nanosecond of data: one per period of each configured stream (a stream without
/// a period counted at the IMU's).
double inputsPerNs(const FilterConfig& c) {
  double per_ns = 0.0;
  const auto add = [&](const std::optional<InputConfig>& in) {
    const std::int64_t period_ns = in && in->period_ns > 0 ? in->period_ns : c.imu.period_ns;
    if (in && period_ns > 0) per_ns += 1.0 / static_cast<double>(period_ns);
  };
  add(c.imu);
  add(c.gnss_observations);
  if (c.second_gnss_receiver_id) add(c.gnss_observations);
  add(c.gnss_fix);
  add(c.star_tracker);
  return per_ns;
}

/// The inputs `span_ns` of data holds, and a quarter more for jitter and commands.
std::size_t inputsOver(const FilterConfig& c, std::int64_t span_ns) {
  if (span_ns <= 0) return 1;
  return static_cast<std::size_t>(1.25 * inputsPerNs(c) * static_cast<double>(span_ns)) + 16;
}

}  // namespace

FilterPipeline::FilterPipeline(const FilterConfig& config, bus::HealthCounters& health, Sinks sinks)
    : FilterPipeline(config, health, health, std::move(sinks)) {}

FilterPipeline::FilterPipeline(const FilterConfig& config, bus::HealthCounters& health,
                               bus::HealthCounters& imu_health, Sinks sinks)
    : config_(config),
      sinks_(std::move(sinks)),
      sequencer_(expectedStreams(config), config.sequencer_max_wait_ns),
      history_(config.recovery_history_ns, config.recovery_snapshot_period_ns,
               inputsOver(config, config.recovery_history_ns)),
      engine_(config.engine),
      predictor_(config.engine.tuning.gravity, config.low_latency_max_buffered),
      imu_gate_(bus::topic::kImuIncrement, imu_health.stream(bus::topic::kImuIncrement),
                config.time_jump, &time_reference_),
      imu_block_gate_(bus::topic::kImuIncrementBlock,
                      imu_health.stream(bus::topic::kImuIncrementBlock)),
      imu_counters_(imu_health.stream(bus::topic::kImuIncrement)),
      gnss_obs_gate_(bus::topic::kGnssObservations, health.stream(bus::topic::kGnssObservations),
                     config.time_jump, &time_reference_),
      gnss_fix_gate_(bus::topic::kGnssFix, health.stream(bus::topic::kGnssFix), config.time_jump,
                     &time_reference_),
      star_gate_(bus::topic::kStarTracker, health.stream(bus::topic::kStarTracker),
                 config.time_jump, &time_reference_),
      gnss_obs_block_gate_(bus::topic::kGnssObservationsBlock,
                           health.stream(bus::topic::kGnssObservationsBlock)),
      gnss_fix_block_gate_(bus::topic::kGnssFixBlock, health.stream(bus::topic::kGnssFixBlock)),
      star_block_gate_(bus::topic::kStarTrackerBlock, health.stream(bus::topic::kStarTrackerBlock)),
      commands_(config, health.stream(bus::topic::kFilterCommand), sinks_.command_outcome) {
  receivers_judged_ = config.fault_monitor && config.fault_monitor->receivers_judged;
  spare_satellite_lists_.reserve(kSpareSatelliteLists);
  sequencer_.reserve(inputsOver(config, config.sequencer_reserve_ns));
}

std::vector<core::SatelliteObservation> FilterPipeline::spareSatelliteList() {
  if (spare_satellite_lists_.empty()) return {};
  std::vector<core::SatelliteObservation> list = std::move(spare_satellite_lists_.back());
  spare_satellite_lists_.pop_back();
  return list;
}

void FilterPipeline::keepSatelliteList(MergedInput* overwritten) {
  if (overwritten == nullptr || spare_satellite_lists_.size() >= kSpareSatelliteLists) return;
  auto* epoch = std::get_if<GnssEpochInput>(&overwritten->input);
  if (epoch == nullptr || epoch->satellites.capacity() == 0) return;
  spare_satellite_lists_.push_back(std::move(epoch->satellites));
}

void FilterPipeline::queue(bus::StreamGate& gate, StreamId id, std::int64_t time_ns,
                           FilterInput input) {
  if (!ended_streams_.empty()) ended_streams_.erase(id);  // a sample after the end: a new run
  if (sequencer_.late(id, time_ns) && mergeLate(id, time_ns, input)) {
    ++counters_.late_merged;
    return;
  }
  switch (sequencer_.push(id, time_ns, std::move(input))) {
    case InputSequencer<FilterInput>::PushResult::kQueued:
      break;
    case InputSequencer<FilterInput>::PushResult::kLate:  // older than the history reaches
      gate.unaccept(id.sensor_id);
      gate.reject({navbus::REJECT_LATE, "time_gps_ns", static_cast<double>(time_ns)}, id.sensor_id);
      break;
    case InputSequencer<FilterInput>::PushResult::kUnexpected:
      // admit() refuses unconfigured sources before their sequence is tracked; this stays so
      // that a caller which did not go through admit() cannot drop a sample uncounted.
      gate.unaccept(id.sensor_id);
      gate.reject(
          {navbus::REJECT_UNEXPECTED_SOURCE, "sensor_id", static_cast<double>(id.sensor_id)},
          id.sensor_id);
      break;
  }
}

template <class Sample>
bool FilterPipeline::admit(bus::StreamGate& gate, const Sample& msg, StreamId id,
                           const std::optional<InputConfig>& expected) {
  if (!expected) {
    // A stream this configuration does not use (e.g. pseudoranges in loosely coupled mode):
    // counted in the summary, not validated, not a rejection of bad data.
    ++counters_.unused_samples;
    return false;
  }
  if (!sequencer_.expects(id)) {
    // A sensor id this filter was not configured with: refused before its sequence numbers
    // are tracked (they are not this stream's).
    gate.reject({navbus::REJECT_UNEXPECTED_SOURCE, "sensor_id", static_cast<double>(id.sensor_id)},
                id.sensor_id);
    return false;
  }
  return gate.admit(msg, id.sensor_id, msg.seq(), msg.time_gps_ns());
}

template <class Sample, class Use>
bool FilterPipeline::admitOrHold(bus::StreamGate& gate, HeldSamples<Sample>& held,
                                 const Sample& msg, StreamId id,
                                 const std::optional<InputConfig>& expected, Use use) {
  if (!admit(gate, msg, id, expected)) {
    held.afterRefusal(gate, id.sensor_id, msg);
    return false;
  }
  for (const Sample& confirmed : held.afterAdmission(gate, id.sensor_id)) use(confirmed);
  return true;
}

void FilterPipeline::onImu(const navbus::ImuIncrement& msg) {
  const auto use = [this](const navbus::ImuIncrement& m) { useImu(m); };
  if (!admitOrHold(imu_gate_, imu_held_, msg, {kRankImu, msg.sensor_id()}, config_.imu, use))
    return;
  if (imu_gate_.sourceRestarted()) startNewRun();
  useImu(msg);
}

void FilterPipeline::useImu(const navbus::ImuIncrement& msg) {
  core::ImuIncrement inc = config_.imu_mounting.toBody(bus::toCore(msg));
  inc.time_ns += config_.imu.time_offset_ns;
  queue(imu_gate_, {kRankImu, msg.sensor_id()}, inc.time_ns, inc);
  if (config_.low_latency_output && sinks_.low_latency) publishLowLatency(inc);
}

void FilterPipeline::onImuBlock(const navbus::ImuIncrementBlock& msg) {
  const auto& increments = msg.increments();
  const std::uint64_t first_ns = increments.empty() ? 0 : increments.front().time_gps_ns();
  // Another unit's block is refused whole, under its id on the block topic (its increments
  // were once taken in and refused one by one under the increment topic, and the block counted
  // as accepted).
  if (!sequencer_.expects({kRankImu, msg.sensor_id()})) {
    imu_block_gate_.reject(
        {navbus::REJECT_UNEXPECTED_SOURCE, "sensor_id", static_cast<double>(msg.sensor_id())},
        msg.sensor_id());
    return;
  }
  if (!imu_block_gate_.admit(msg, msg.sensor_id(), msg.seq(), first_ns)) return;
  for (const navbus::ImuIncrement& increment : increments) {
    ++imu_counters_.received;
    onImu(increment);
  }
}

void FilterPipeline::publishLowLatency(const core::ImuIncrement& inc) {
  const std::optional<core::NavState> s = predictor_.addIncrement(inc);
  if (!s) return;
  sinks_.low_latency(lowLatencySolution(anchor_solution_, *s, ++low_latency_seq_));
}

void FilterPipeline::onGnssObservations(const navbus::GnssObservationEpoch& m) {
  const auto use = [this](const navbus::GnssObservationEpoch& e) { useGnssObservations(e); };
  if (admitOrHold(gnss_obs_gate_, gnss_obs_held_, m, {kRankGnssObs, m.receiver_id()},
                  config_.gnss_observations, use))
    useGnssObservations(m);
}

void FilterPipeline::useGnssObservations(const navbus::GnssObservationEpoch& m) {
  // A bad satellite costs that satellite only (counted per reason); the others are used.
  const std::vector<bus::SatelliteRejection> dropped =
      bus::screenSatellites(m, gnss_obs_gate_.limits());
  for (const bus::SatelliteRejection& d : dropped)
    gnss_obs_gate_.rejectElement(d.rejection, m.receiver_id());
  const std::int64_t time_ns =
      static_cast<std::int64_t>(m.time_gps_ns()) + config_.gnss_observations->time_offset_ns;
  GnssEpochInput epoch{time_ns, spareSatelliteList()};
  bus::toCore(m, dropped, epoch.satellites);
  queue(gnss_obs_gate_, {kRankGnssObs, m.receiver_id()}, time_ns, std::move(epoch));
}

void FilterPipeline::onGnssFix(const navbus::GnssFix& m) {
  const auto use = [this](const navbus::GnssFix& f) { useGnssFix(f); };
  if (admitOrHold(gnss_fix_gate_, gnss_fix_held_, m, {kRankGnssFix, m.receiver_id()},
                  config_.gnss_fix, use))
    useGnssFix(m);
}

void FilterPipeline::useGnssFix(const navbus::GnssFix& m) {
  core::GnssFixMeasurement fix = bus::toCore(m);
  fix.time_ns += config_.gnss_fix->time_offset_ns;
  fix.velocity_time_offset_ns = config_.gnss_fix->velocity_time_offset_ns;
  queue(gnss_fix_gate_, {kRankGnssFix, m.receiver_id()}, fix.time_ns, fix);
}

void FilterPipeline::onStarTracker(const navbus::StarTrackerAttitude& m) {
  const auto use = [this](const navbus::StarTrackerAttitude& a) { useStarTracker(a); };
  if (admitOrHold(star_gate_, star_held_, m, {kRankStarTracker, m.tracker_id()},
                  config_.star_tracker, use))
    useStarTracker(m);
}

template <class Block, class Take>
void FilterPipeline::takeBlock(const Block& msg, bus::StreamGate& block_gate,
                               bus::StreamGate& element_gate, Take take) {
  const auto& elements = bus::SensorBlock<Block>::elements(msg);
  const std::uint64_t first_ns = elements.empty() ? 0 : elements.front().time_gps_ns();
  if (!block_gate.admit(msg, bus::SensorMessage<Block>::sensorId(msg), msg.seq(), first_ns)) return;
  for (const auto& element : elements) {
    ++element_gate.counters().received;
    take(element);
  }
}

void FilterPipeline::onGnssObservationsBlock(const navbus::GnssObservationEpochBlock& msg) {
  takeBlock(msg, gnss_obs_block_gate_, gnss_obs_gate_,
            [this](const navbus::GnssObservationEpoch& m) { onGnssObservations(m); });
}

void FilterPipeline::onGnssFixBlock(const navbus::GnssFixBlock& msg) {
  takeBlock(msg, gnss_fix_block_gate_, gnss_fix_gate_,
            [this](const navbus::GnssFix& m) { onGnssFix(m); });
}

void FilterPipeline::onStarTrackerBlock(const navbus::StarTrackerAttitudeBlock& msg) {
  takeBlock(msg, star_block_gate_, star_gate_,
            [this](const navbus::StarTrackerAttitude& m) { onStarTracker(m); });
}

void FilterPipeline::useStarTracker(const navbus::StarTrackerAttitude& m) {
  core::StarAttitudeMeasurement st = bus::toCore(m);
  st.time_ns += config_.star_tracker->time_offset_ns;
  queue(star_gate_, {kRankStarTracker, m.tracker_id()}, st.time_ns, st);
}

void FilterPipeline::startNewRun() {
  flush(last_pump_ns_);
  const std::size_t dropped = sequencer_.newRun({kRankImu, config_.imu.id});
  counters_.solutions_earlier_runs += solution_seq_;
  counters_.increments_earlier_runs += engine_.counters().imu_used;
  engine_ = core::NavigationEngine(config_.engine);
  history_ =
      InputHistory<MergedInput>(config_.recovery_history_ns, config_.recovery_snapshot_period_ns);
  replay_.clear();
  predictor_.reset();
  low_latency_seq_ = 0;
  first_input_ns_ = -1;
  solution_seq_ = 0;
  diagnostics_seq_ = 0;
  published_up_to_ns_ = -1;
  diagnosed_up_to_ns_ = -1;
  owed_judgement_ns_ = -1;
  judged_up_to_ns_ = -1;
  judgements_.newRun();
  gnss_judged_passed_ns_ = 0;
  time_reference_.latest_ns = 0;
  for (bus::StreamGate* g : {&gnss_obs_gate_, &gnss_fix_gate_, &star_gate_})
    g->tracker().resetAll();
  gnss_obs_held_.clear();
  gnss_fix_held_.clear();
  star_held_.clear();
  ++counters_.new_runs;
  spdlog::warn(
      "the IMU source restarted at an earlier time: new run {} (the filter starts over; "
      "{} held inputs of the previous run could not be released)",
      counters_.new_runs, dropped);
}

void FilterPipeline::onStreamEnded(bus::StreamKind kind, std::uint32_t id) {
  const bus::StreamKindInfo& stream = bus::streamInfo(kind);
  if (stream.merge_rank == bus::kNotMerged) return;
  if (!sequencer_.setActive({stream.merge_rank, id}, false)) return;  // a stream not in use
  ended_streams_.insert({stream.merge_rank, id});
  if (kind == bus::StreamKind::kGnssObservations && fusedReceiverEnded())  // no next epoch
    sequencer_.setActive(kGnssJudgementStream, false);                     // to judge
  spdlog::info("{} id {} ended (its writer disposed it): no longer waited for", stream.topic, id);
}

void FilterPipeline::pump(std::int64_t now_ns) {
  last_pump_ns_ = now_ns;
  checkImuWriters(now_ns);
  sequencer_.release(now_ns, [this](StreamId id, std::int64_t time_ns, FilterInput& in) {
    process(id, time_ns, std::move(in));
  });
}

void FilterPipeline::resumedAfterStall(std::int64_t now_ns, std::int64_t stalled_ns) {
  sequencer_.restartWait(now_ns);
  if (imu_writers_since_ns_ >= 0) imu_writers_since_ns_ = now_ns;
  ++counters_.stalls;
  counters_.longest_stall_ns = std::max(counters_.longest_stall_ns, stalled_ns);
  spdlog::warn("filter not running for {:.3f} s (stopped, starved of CPU): waits start again",
               1e-9 * static_cast<double>(stalled_ns));
}

void FilterPipeline::flush(std::int64_t now_ns) {
  sequencer_.setActive(kCommandStream, false);  // nothing more will be judged
  sequencer_.setActive(kImuJudgementStream, false);
  sequencer_.setActive(kGnssJudgementStream, false);
  for (int round = 0; round < 8 && sequencer_.pending() > 0; ++round) {  // a stream a round
    now_ns += config_.sequencer_max_wait_ns;
    pump(now_ns);
  }
  fuseHeldEpoch();              // a receiver's epoch whose companion never came
  engine_.closeSmoothingLog();  // post-processing: the last epoch's updates
}

void FilterPipeline::process(StreamId stream, std::int64_t time_ns, FilterInput&& owned) {
  if (const auto* cmd = std::get_if<CommandInput>(&owned);
      cmd != nullptr && !replaying_ && !cmd->reapply) {
    executeCommand(cmd->command);  // checks, records and applies it (or restores and replays)
    return;
  }
  // Epochs of several receivers held for one stacked update: fused before anything that does
  // not join them (the IMU's next increment at the latest).
  if (engine_.hasHeldEpoch()) {
    const auto* next = std::get_if<GnssEpochInput>(&owned);
    if (next == nullptr || !engine_.joinsHeldEpoch(time_ns, receiverIndex(stream.sensor_id)))
      fuseHeldEpoch();
  }
  keepSatelliteList(history_.overwritten());
  // Kept by the history (moved, not copied) and processed from there.
  const FilterInput& input =
      history_.record(time_ns, {stream, time_ns, std::move(owned)}, engine_).input;
  if (first_input_ns_ < 0 && !std::holds_alternative<CommandInput>(input))
    first_input_ns_ = time_ns;
  if (const auto* inc = std::get_if<core::ImuIncrement>(&input)) {
    // A parity test judges the IMU data itself: a command answering it takes its place in the
    // order as offline (nothing later is released before this time is judged).
    if (owe_imu_judgement_ && !replaying_) sequencer_.owe(kImuJudgementStream, time_ns);
    if (engine_.addImu(*inc) && !replaying_ && time_ns > published_up_to_ns_) {
      published_up_to_ns_ = time_ns;  // each solution time once, also after a rewind
      publishSolution();
    }
  } else if (const auto* epoch = std::get_if<GnssEpochInput>(&input)) {
    // The next epoch waits for the receivers' judgement of the time before it: a command
    // about it (a clock jump, a satellite) then comes before it in the order, as offline.
    if (receivers_judged_ && !replaying_)
      sequencer_.owe(kGnssJudgementStream, time_ns + config_.gnss_observations->period_ns - 1);
    if (config_.second_gnss_receiver_id) {
      engine_.holdGnssEpoch(epoch->time_ns, epoch->satellites, receiverIndex(stream.sensor_id));
      if (engine_.heldEpochComplete()) fuseHeldEpoch();
    } else if (engine_.addGnssEpoch(epoch->time_ns, epoch->satellites)) {
      diagnoseEpoch(time_ns);
    }
  } else if (const auto* fix = std::get_if<core::GnssFixMeasurement>(&input)) {
    engine_.addGnssFix(*fix);
  } else if (const auto* st = std::get_if<core::StarAttitudeMeasurement>(&input)) {
    engine_.addStarAttitude(*st);
  } else if (const auto* cmd = std::get_if<CommandInput>(&input)) {
    applyToEngine(cmd->command);  // re-processed after a rollback: checked when it first came
  }
}

int FilterPipeline::receiverIndex(std::uint32_t receiver_id) const {
  return config_.second_gnss_receiver_id && receiver_id == *config_.second_gnss_receiver_id ? 1 : 0;
}

bool FilterPipeline::fusedReceiverEnded() const {
  if (!config_.gnss_observations) return true;
  const bool first = ended_streams_.count({kRankGnssObs, config_.gnss_observations->id}) > 0;
  if (!config_.second_gnss_receiver_id) return first;
  return first && ended_streams_.count({kRankGnssObs, *config_.second_gnss_receiver_id}) > 0;
}

void FilterPipeline::fuseHeldEpoch() {
  if (!engine_.hasHeldEpoch()) return;
  const std::int64_t time_ns = engine_.heldEpochTime();
  if (engine_.fuseHeldEpoch()) diagnoseEpoch(time_ns);
}

void FilterPipeline::diagnoseEpoch(std::int64_t time_ns) {
  if (replaying_ || time_ns <= diagnosed_up_to_ns_) return;  // each epoch once, also after a rewind
  diagnosed_up_to_ns_ = time_ns;
  publishDiagnostics();
}

bool FilterPipeline::mergeLate(StreamId id, std::int64_t time_ns, FilterInput& input) {
  const std::optional<std::int64_t> kept_up_to = history_.rewindBefore(time_ns, engine_, replay_);
  if (!kept_up_to) return false;
  for (MergedInput& item : replay_) {
    if (auto* cmd = std::get_if<CommandInput>(&item.input)) cmd->reapply = true;
  }
  sequencer_.rewind(*kept_up_to, replay_);
  replay_.clear();
  ++counters_.rewinds;
  if (sequencer_.push(id, time_ns, std::move(input)) !=
      InputSequencer<FilterInput>::PushResult::kQueued)
    return false;
  return true;
}

void FilterPipeline::publishDiagnostics() {
  if (!sinks_.diagnostics) return;
  owed_judgement_ns_ = engine_.state().time_ns;
  sequencer_.owe(kCommandStream, owed_judgement_ns_);  // a command may answer it
  const bus::FusedReceiverIds receivers{
      config_.gnss_observations ? config_.gnss_observations->id : 0U,
      config_.second_gnss_receiver_id.value_or(0U)};
  navbus::FilterDiagnostics msg =
      bus::toIdl(engine_.lastEpoch(), config_.vehicle_id, ++diagnostics_seq_,
                 engine_.state().time_ns, receivers);
  appendNoiseScales(engine_, msg);
  sinks_.diagnostics(msg);
}

bool FilterPipeline::monitored() const {
  if (judgements_.reports() == 0 || owed_judgement_ns_ < 0) return flags_.faultMonitorAlive();
  return judged_up_to_ns_ >= owed_judgement_ns_;
}

void FilterPipeline::publishSolution() {
  if (!engine_.initialized()) return;
  const bool monitored_now = monitored();
  const std::uint32_t flags = (flags_.flags() & ~navbus::FAULT_NO_FAULT_MONITOR) |
                              (monitored_now ? 0U : navbus::FAULT_NO_FAULT_MONITOR);
  navbus::NavigationSolution sol =
      buildSolution(engine_, config_.vehicle_id, ++solution_seq_, flags, monitored_now);
  sol.lane_id(config_.imu.id);
  counters_.solutions_untrusted += sol.covariance_valid() ? 0 : 1;
  sinks_.solution(sol);
  if (config_.low_latency_output && sinks_.low_latency) {
    predictor_.setAnchor({engine_.state(), engine_.imuCorrection()});
    anchor_solution_ = sol;
  }
}

void FilterPipeline::publishHeldSolution() {
  if (engine_.mode() == core::EngineMode::kInertialLost) publishSolution();
}

std::string FilterPipeline::summary() const {
  return describePipeline({config_, engine_, commands_.counters(), flags_, predictor_.counters(),
                           counters_, solution_seq_, sequencer_.timeouts(), sequencer_.pending(),
                           sequencer_.grown(), judgements_.reports(), judgements_.heldForCommand(),
                           sequencer_.judgementTimeouts()});
}

}  // namespace navbus::nav_filter
