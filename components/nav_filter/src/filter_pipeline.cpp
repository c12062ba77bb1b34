#include "navbus/nav_filter/filter_pipeline.hpp"

#include <algorithm>
#include <array>

#include <cmath>
#include <sstream>
#include <type_traits>

#include <spdlog/spdlog.h>

#include "navbus/bus/conversions.hpp"
#include "navbus/bus/topics.hpp"

namespace navbus::nav_filter {

namespace {

std::vector<InputSequencer<FilterInput>::ExpectedStream> expectedStreams(const FilterConfig& c) {
  std::vector<InputSequencer<FilterInput>::ExpectedStream> s;
  s.push_back({{kRankImu, c.imu.id}, c.imu.period_ns});
  if (c.gnss_observations)
    s.push_back({{kRankGnssObs, c.gnss_observations->id}, c.gnss_observations->period_ns});
  if (c.gnss_fix) s.push_back({{kRankGnssFix, c.gnss_fix->id}, c.gnss_fix->period_ns});
  if (c.star_tracker)
    s.push_back({{kRankStarTracker, c.star_tracker->id}, c.star_tracker->period_ns});
  s.push_back({{kRankCommand, 0}, 0, true});
  return s;
}

constexpr std::uint32_t kStreamLostFlags =
    navbus::FAULT_IMU_STREAM_LOST | navbus::FAULT_GNSS_STREAM_LOST | navbus::FAULT_ST_STREAM_LOST |
    navbus::FAULT_RAW_IMU_LOST;

std::uint32_t faultFlags(std::uint32_t engine_status) {
  std::uint32_t f = 0;
  if (engine_status & core::kStatusImuGap) f |= navbus::FAULT_IMU_GAP;
  if (engine_status & core::kStatusSatelliteExcluded) f |= navbus::FAULT_SATELLITE_EXCLUDED;
  if (engine_status & core::kStatusBiasCompensated) f |= navbus::FAULT_SENSOR_AXIS;
  if (engine_status & core::kStatusAxisFailed) f |= navbus::FAULT_IMU_AXIS_FAILED;
  return f;
}

}  // namespace

navbus::IntegrityState toIdl(core::IntegrityState s) {
  switch (s) {
    case core::IntegrityState::kNotMonitored:
      return navbus::INTEGRITY_NOT_MONITORED;
    case core::IntegrityState::kInitializing:
      return navbus::INTEGRITY_INITIALIZING;
    case core::IntegrityState::kAvailable:
      return navbus::INTEGRITY_AVAILABLE;
    case core::IntegrityState::kUnavailable:
      return navbus::INTEGRITY_UNAVAILABLE;
  }
  return navbus::INTEGRITY_NOT_MONITORED;
}

navbus::FilterMode toIdl(core::EngineMode mode) {
  switch (mode) {
    case core::EngineMode::kInitializing:
      return navbus::MODE_INITIALIZING;
    case core::EngineMode::kInertialOnly:
      return navbus::MODE_INERTIAL_ONLY;
    case core::EngineMode::kInertialLost:
      return navbus::MODE_INERTIAL_LOST;
    case core::EngineMode::kTightlyCoupled:
      return navbus::MODE_TIGHTLY_COUPLED;
    case core::EngineMode::kLooselyCoupled:
      return navbus::MODE_LOOSELY_COUPLED;
    case core::EngineMode::kMdfF1:
      return navbus::MODE_MDF_F1_ZUPT;
    case core::EngineMode::kMdfF2:
      return navbus::MODE_MDF_F2_GNSS;
    case core::EngineMode::kMdfF3:
      return navbus::MODE_MDF_F3_RECOVERY;
    case core::EngineMode::kMdfF4:
      return navbus::MODE_MDF_F4_CIF;
    case core::EngineMode::kAidedAxisFailed:
      return navbus::MODE_AIDED_AXIS_FAILED;
    case core::EngineMode::kAligning:
      return navbus::MODE_ALIGNING;
  }
  return navbus::MODE_INITIALIZING;
}

navbus::StartSource toIdl(core::StartSource start, core::AttitudeSource attitude) {
  if (start == core::StartSource::kConfigured) return navbus::START_CONFIGURED;
  switch (attitude) {
    case core::AttitudeSource::kStarTracker:
      return navbus::START_STAR_TRACKER;
    case core::AttitudeSource::kGyrocompass:
      return navbus::START_GYROCOMPASS;
    case core::AttitudeSource::kGnssCourse:
      return navbus::START_GNSS_COURSE;
    case core::AttitudeSource::kNone:
      break;  // not aligned yet: no solution is published
  }
  return navbus::START_CONFIGURED;
}

navbus::FusionStructure toIdl(core::FusionStructure s, core::AidingMode aiding) {
  if (aiding == core::AidingMode::kInertialOnly) return navbus::FUSION_NONE;
  switch (s) {
    case core::FusionStructure::kCentralized:
      return navbus::FUSION_CENTRALIZED;
    case core::FusionStructure::kFederated:
      return navbus::FUSION_FEDERATED;
    case core::FusionStructure::kAdaptive:
      return navbus::FUSION_ADAPTIVE;
  }
  return navbus::FUSION_NONE;
}

FilterPipeline::FilterPipeline(const FilterConfig& config, bus::HealthCounters& health, Sinks sinks)
    : config_(config),
      sinks_(std::move(sinks)),
      sequencer_(expectedStreams(config), config.sequencer_max_wait_ns),
      history_(config.recovery_history_ns, config.recovery_snapshot_period_ns),
      engine_(config.engine),
      predictor_(config.engine.tuning.gravity, config.low_latency_max_buffered),
      imu_gate_(bus::topic::kImuIncrement, health.stream(bus::topic::kImuIncrement),
                config.time_jump, &time_reference_),
      imu_block_gate_(bus::topic::kImuIncrementBlock,
                      health.stream(bus::topic::kImuIncrementBlock)),
      imu_counters_(health.stream(bus::topic::kImuIncrement)),
      gnss_obs_gate_(bus::topic::kGnssObservations, health.stream(bus::topic::kGnssObservations),
                     config.time_jump, &time_reference_),
      gnss_fix_gate_(bus::topic::kGnssFix, health.stream(bus::topic::kGnssFix), config.time_jump,
                     &time_reference_),
      star_gate_(bus::topic::kStarTracker, health.stream(bus::topic::kStarTracker),
                 config.time_jump, &time_reference_),
      command_counters_(health.stream(bus::topic::kFilterCommand)) {}

void FilterPipeline::countCommand(bool applied, navbus::RejectReason reason) {
  if (applied) {
    ++commands_applied_;
    ++command_counters_.accepted;
  } else {
    ++commands_refused_;
    ++command_counters_.rejected[reason];
  }
}

void FilterPipeline::queue(bus::StreamGate& gate, StreamId id, std::int64_t time_ns,
                           FilterInput input) {
  switch (sequencer_.push(id, time_ns, std::move(input))) {
    case InputSequencer<FilterInput>::PushResult::kQueued:
      break;
    case InputSequencer<FilterInput>::PushResult::kLate:
      gate.unaccept();
      gate.reject({navbus::REJECT_LATE, "time_gps_ns", static_cast<double>(time_ns)}, id.sensor_id);
      break;
    case InputSequencer<FilterInput>::PushResult::kUnexpected:
      // admit() refuses unconfigured sources before their sequence is tracked; this stays so
      // that a caller which did not go through admit() cannot drop a sample uncounted.
      gate.unaccept();
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
    ++unused_samples_;
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

void FilterPipeline::onImu(const navbus::ImuIncrement& msg) {
  if (!admit(imu_gate_, msg, {kRankImu, msg.sensor_id()}, config_.imu)) return;
  if (imu_gate_.sourceRestarted()) startNewRun();
  const core::ImuIncrement inc = bus::toCore(msg);
  queue(imu_gate_, {kRankImu, msg.sensor_id()}, inc.time_ns, inc);
  if (config_.low_latency_output && sinks_.low_latency) publishLowLatency(inc);
}

void FilterPipeline::onImuBlock(const navbus::ImuIncrementBlock& msg) {
  const auto& increments = msg.increments();
  const std::uint64_t first_ns = increments.empty() ? 0 : increments.front().time_gps_ns();
  if (!imu_block_gate_.admit(msg, msg.sensor_id(), msg.seq(), first_ns)) return;
  for (const navbus::ImuIncrement& increment : increments) {
    ++imu_counters_.received;
    onImu(increment);
  }
}

void FilterPipeline::publishLowLatency(const core::ImuIncrement& inc) {
  const std::optional<core::NavState> s = predictor_.addIncrement(inc);
  if (!s) return;
  navbus::NavigationSolution out = anchor_solution_;
  out.seq(++low_latency_seq_);
  bus::fillSolution(*s, out);
  out.output(navbus::OUTPUT_LOW_LATENCY);
  out.propagated_from_gps_ns(anchor_solution_.time_gps_ns());
  sinks_.low_latency(out);
}

void FilterPipeline::onGnssObservations(const navbus::GnssObservationEpoch& m) {
  if (!admit(gnss_obs_gate_, m, {kRankGnssObs, m.receiver_id()}, config_.gnss_observations)) return;
  // A bad satellite costs that satellite only (counted per reason); the others are used.
  const std::vector<bus::SatelliteRejection> dropped =
      bus::screenSatellites(m, gnss_obs_gate_.limits());
  for (const bus::SatelliteRejection& d : dropped)
    gnss_obs_gate_.rejectElement(d.rejection, m.receiver_id());
  queue(gnss_obs_gate_, {kRankGnssObs, m.receiver_id()}, static_cast<std::int64_t>(m.time_gps_ns()),
        GnssEpochInput{static_cast<std::int64_t>(m.time_gps_ns()), bus::toCore(m, dropped)});
}

void FilterPipeline::onGnssFix(const navbus::GnssFix& m) {
  if (!admit(gnss_fix_gate_, m, {kRankGnssFix, m.receiver_id()}, config_.gnss_fix)) return;
  queue(gnss_fix_gate_, {kRankGnssFix, m.receiver_id()}, static_cast<std::int64_t>(m.time_gps_ns()),
        bus::toCore(m));
}

void FilterPipeline::onStarTracker(const navbus::StarTrackerAttitude& m) {
  if (!admit(star_gate_, m, {kRankStarTracker, m.tracker_id()}, config_.star_tracker)) return;
  queue(star_gate_, {kRankStarTracker, m.tracker_id()}, static_cast<std::int64_t>(m.time_gps_ns()),
        bus::toCore(m));
}

void FilterPipeline::startNewRun() {
  flush(last_pump_ns_);
  const std::size_t dropped = sequencer_.newRun({kRankImu, config_.imu.id});
  solutions_earlier_runs_ += solution_seq_;
  increments_earlier_runs_ += engine_.counters().imu_used;
  engine_ = core::NavigationEngine(config_.engine);
  history_ =
      InputHistory<FilterInput>(config_.recovery_history_ns, config_.recovery_snapshot_period_ns);
  replay_.clear();
  predictor_.reset();
  low_latency_seq_ = 0;
  first_input_ns_ = -1;
  solution_seq_ = 0;
  diagnostics_seq_ = 0;
  time_reference_.latest_ns = 0;
  for (bus::StreamGate* g : {&gnss_obs_gate_, &gnss_fix_gate_, &star_gate_})
    g->tracker().resetAll();
  ++new_runs_;
  spdlog::warn(
      "the IMU source restarted at an earlier time: new run {} (the filter starts over; "
      "{} held inputs of the previous run could not be released)",
      new_runs_, dropped);
}

void FilterPipeline::onStreamEnded(StreamRank rank, std::uint32_t id) {
  static constexpr std::array<const char*, 4> kTopics{
      bus::topic::kImuIncrement, bus::topic::kGnssObservations, bus::topic::kGnssFix,
      bus::topic::kStarTracker};
  if (!sequencer_.setActive({rank, id}, false)) return;  // a stream this filter does not use
  spdlog::info("{} id {} ended (its writer disposed it): no longer waited for",
               rank < static_cast<int>(kTopics.size()) ? kTopics[rank] : "command", id);
}

void FilterPipeline::pump(std::int64_t now_ns) {
  last_pump_ns_ = now_ns;
  sequencer_.release(now_ns, [this](StreamId, std::int64_t time_ns, const FilterInput& in) {
    process(time_ns, in);
  });
}

void FilterPipeline::flush(std::int64_t now_ns) {
  // Each round may set one silent stream aside after the bounded wait; there are at most as
  // many rounds as streams.
  for (int round = 0; round < 8 && sequencer_.pending() > 0; ++round) {
    now_ns += config_.sequencer_max_wait_ns;
    pump(now_ns);
  }
}

std::int64_t FilterPipeline::timeOf(const FilterInput& input) {
  return std::visit([](const auto& in) -> std::int64_t { return in.time_ns; }, input);
}

void FilterPipeline::process(std::int64_t time_ns, const FilterInput& input) {
  if (const auto* cmd = std::get_if<CommandInput>(&input); cmd != nullptr && !replaying_) {
    executeCommand(cmd->command);  // checks, records and applies it (or restores and replays)
    return;
  }
  history_.record(time_ns, input, engine_);
  if (first_input_ns_ < 0 && !std::holds_alternative<CommandInput>(input))
    first_input_ns_ = time_ns;
  if (const auto* inc = std::get_if<core::ImuIncrement>(&input)) {
    if (engine_.addImu(*inc) && !replaying_) publishSolution();
  } else if (const auto* epoch = std::get_if<GnssEpochInput>(&input)) {
    if (engine_.addGnssEpoch(epoch->time_ns, epoch->satellites) && !replaying_)
      publishDiagnostics();
  } else if (const auto* fix = std::get_if<core::GnssFixMeasurement>(&input)) {
    engine_.addGnssFix(*fix);
  } else if (const auto* st = std::get_if<core::StarAttitudeMeasurement>(&input)) {
    engine_.addStarAttitude(*st);
  } else if (const auto* cmd = std::get_if<CommandInput>(&input)) {
    applyToEngine(cmd->command);  // re-processed after a rollback: checked when it first came
  }
}

void FilterPipeline::publishDiagnostics() {
  if (!sinks_.diagnostics) return;
  sinks_.diagnostics(bus::toIdl(engine_.lastEpoch(), config_.vehicle_id, ++diagnostics_seq_,
                                engine_.state().time_ns));
}

void FilterPipeline::publishSolution() {
  if (!engine_.initialized()) return;
  navbus::NavigationSolution sol;
  sol.vehicle_id(config_.vehicle_id);
  sol.seq(++solution_seq_);
  bus::fillSolution(engine_.state(), sol);
  // Sigmas from the filter covariance: propagated only (inertial-only mode) or updated.
  const core::StateMatrix& P = engine_.covariance();
  auto sigma3 = [&P](const core::StateBlock& b) {
    return bus::toArray(P.block<3, 3>(b.index, b.index).diagonal().cwiseSqrt());
  };
  sol.pos_sigma_ned_m(sigma3(core::layout::kPos));
  sol.vel_sigma_ned_mps(sigma3(core::layout::kVel));
  sol.att_sigma_ned_rad(sigma3(core::layout::kAtt));
  sol.accel_bias_sigma_b_mps2(sigma3(core::layout::kAccelBias));
  sol.gyro_bias_sigma_b_radps(sigma3(core::layout::kGyroBias));
  sol.clock_bias_m(engine_.clockBias());
  sol.clock_drift_mps(engine_.clockDrift());
  sol.clock_bias_sigma_m(
      std::sqrt(P(core::layout::kClockBias.index, core::layout::kClockBias.index)));
  sol.clock_drift_sigma_mps(
      std::sqrt(P(core::layout::kClockDrift.index, core::layout::kClockDrift.index)));
  sol.covariance_valid(true);
  // Biases: estimated plus those compensated by command.
  sol.accel_bias_b_mps2(bus::toArray(engine_.accelBias()));
  sol.gyro_bias_b_radps(bus::toArray(engine_.gyroBias()));
  sol.mode(toIdl(engine_.mode()));
  sol.fusion(toIdl(engine_.fusion(), config_.engine.aiding));
  sol.active_fault_flags(stream_flags_ | monitor_flags_ | faultFlags(engine_.status()));
  sol.imu_samples_used(engine_.counters().imu_used);
  sol.start_source(toIdl(config_.engine.start, engine_.alignedStart().attitude_source));
  // The levels assume the fault manager's GLR is watching: without it nothing bounds a fault.
  if (monitor_flags_ == 0) {
    const core::ProtectionLevels pl = engine_.protectionLevels();
    sol.integrity(toIdl(pl.state));
    sol.horizontal_protection_level_m(pl.horizontal_m);
    sol.vertical_protection_level_m(pl.vertical_m);
  }
  sinks_.solution(sol);
  if (config_.low_latency_output && sinks_.low_latency) {
    predictor_.setAnchor({engine_.state(), engine_.accelBias(), engine_.gyroBias()});
    anchor_solution_ = sol;
  }
}

void FilterPipeline::publishHeldSolution() {
  if (engine_.mode() == core::EngineMode::kInertialLost) publishSolution();
}

bool FilterPipeline::degraded() const {
  return (stream_flags_ & kStreamLostFlags) != 0 || monitor_flags_ != 0;
}

void FilterPipeline::setFaultMonitorAlive(bool alive) {
  const std::uint32_t flags = alive ? 0 : navbus::FAULT_NO_FAULT_MONITOR;
  if (flags == monitor_flags_) return;
  monitor_flags_ = flags;
  if (alive) {
    spdlog::info("a fault monitor is alive again: faults are monitored");
  } else {
    ++monitor_losses_;
    spdlog::warn("no fault monitor is alive: solutions flagged FAULT_NO_FAULT_MONITOR");
  }
}

void FilterPipeline::onDecision(const navbus::FaultDecision& d) {
  // Decisions are facts (idl/Fault.idl): the filter acts on commands only. It counts what it
  // saw so that the summary shows decisions that came without a command.
  ++decisions_seen_;
  spdlog::info("decision {} ({}): event {} source {} sv {} axis {} statistic {:.4g} / {:.4g}",
               d.decision_id(), d.detector(), static_cast<int>(d.event()),
               static_cast<int>(d.source()), d.sv_id(), d.axis(), d.test_statistic(),
               d.threshold());
}

bool FilterPipeline::applyStreamCommand(const navbus::FilterCommand& c) {
  std::uint32_t flag = 0;
  bool is_imu = false;
  switch (c.sensor()) {
    case navbus::SOURCE_IMU_STREAM:
      if (c.sensor_id() != config_.imu.id) return false;
      flag = navbus::FAULT_IMU_STREAM_LOST;
      is_imu = true;
      break;
    case navbus::SOURCE_IMU_RAW_STREAM:
      flag = navbus::FAULT_RAW_IMU_LOST;
      break;
    case navbus::SOURCE_GNSS_OBS_STREAM:
    case navbus::SOURCE_GNSS_FIX_STREAM:
      flag = navbus::FAULT_GNSS_STREAM_LOST;
      break;
    case navbus::SOURCE_ST_STREAM:
      flag = navbus::FAULT_ST_STREAM_LOST;
      break;
    default:
      return false;
  }
  if (c.kind() == navbus::CMD_EXCLUDE_STREAM) {
    stream_flags_ |= flag;
    if (is_imu) {
      sequencer_.setActive({kRankImu, config_.imu.id}, false);
      engine_.markInertialLost();
    }
  } else {
    stream_flags_ &= ~flag;
  }
  spdlog::log(c.kind() == navbus::CMD_EXCLUDE_STREAM ? spdlog::level::warn : spdlog::level::info,
              "stream source {} id {} {}; flags 0x{:x}", static_cast<int>(c.sensor()),
              c.sensor_id(), c.kind() == navbus::CMD_EXCLUDE_STREAM ? "lost" : "restored",
              stream_flags_);
  publishHeldSolution();
  return true;
}

bool FilterPipeline::issuerAuthorized(const navbus::FilterCommand& c,
                                      const std::optional<std::string>& writer_identity) {
  const std::string issuer = c.issuer().to_string();
  if (std::find(config_.command_issuers.begin(), config_.command_issuers.end(), issuer) ==
      config_.command_issuers.end()) {
    countCommand(false, navbus::REJECT_UNAUTHORIZED);
    ++commands_unauthorized_;
    spdlog::warn(
        "command {} (kind {}) from '{}' refused: not a configured issuer "
        "(command_issuers); {} refused so far",
        c.command_id(), static_cast<int>(c.kind()), issuer, commands_unauthorized_);
    return false;
  }
  if (writer_identity && *writer_identity != config_.issuer_identities.at(issuer)) {
    countCommand(false, navbus::REJECT_UNAUTHORIZED);
    ++commands_impersonated_;
    spdlog::warn(
        "command {} (kind {}) claims issuer '{}' but was written by identity '{}' (expected "
        "'{}', issuer_identities): refused; {} refused so far",
        c.command_id(), static_cast<int>(c.kind()), issuer, *writer_identity,
        config_.issuer_identities.at(issuer), commands_impersonated_);
    return false;
  }
  return true;
}

void FilterPipeline::onCommand(const navbus::FilterCommand& c,
                               const std::optional<std::string>& writer_identity) {
  if (c.vehicle_id() != config_.vehicle_id) return;  // for another vehicle: not ours
  if (!issuerAuthorized(c, writer_identity)) return;
  if (c.kind() == navbus::CMD_EXCLUDE_STREAM || c.kind() == navbus::CMD_READMIT_STREAM) {
    // About the merge itself (a lost stream must stop holding it): at once.
    if (refuseIfStale(c)) return;
    const bool applied = applyStreamCommand(c);
    countCommand(applied, navbus::REJECT_UNEXPECTED_SOURCE);
    if (!applied)
      spdlog::warn(
          "command {} from '{}' refused: stream source {} id {} is not a stream of this "
          "filter",
          c.command_id(), c.issuer(), static_cast<int>(c.sensor()), c.sensor_id());
    return;
  }
  const auto time_ns = static_cast<std::int64_t>(c.time_gps_ns());
  if (time_ns > 0 && sequencer_.push({kRankCommand, 0}, time_ns, CommandInput{time_ns, c}) ==
                         InputSequencer<FilterInput>::PushResult::kQueued) {
    return;  // takes effect in order, at its data time
  }
  if (time_ns > 0) ++commands_late_;
  executeCommand(c);
}

bool FilterPipeline::refuseIfStale(const navbus::FilterCommand& c) {
  const auto time_ns = static_cast<std::int64_t>(c.time_gps_ns());
  if (time_ns == 0 || (first_input_ns_ >= 0 && time_ns >= first_input_ns_)) return false;
  countCommand(false, navbus::REJECT_STALE);
  ++commands_stale_;
  spdlog::warn(
      "command {} (kind {}, decision {}) from '{}' refused: stale, about data at {:.3f} s, "
      "before this run's first input{}; {} stale so far",
      c.command_id(), static_cast<int>(c.kind()), c.decision_id(), c.issuer(),
      1e-9 * static_cast<double>(time_ns),
      first_input_ns_ < 0
          ? " (none yet)"
          : fmt::format(" at {:.3f} s", 1e-9 * static_cast<double>(first_input_ns_)),
      commands_stale_);
  return true;
}

void FilterPipeline::executeCommand(const navbus::FilterCommand& c) {
  if (refuseIfStale(c)) return;
  std::string why;
  bool applied = false;
  navbus::RejectReason reason = navbus::REJECT_NOT_APPLICABLE;
  if (auto refusal = checkCommand(c)) {
    why = *refusal;
    reason = navbus::REJECT_OUT_OF_RANGE;
  } else if (recoversFromOnset(c) && history_.rollback(restorePoint(c), engine_, replay_)) {
    // Restored to before the onset: the command applies there, and what followed is
    // re-processed without the fault (nothing is published meanwhile: those solutions went out).
    const std::int64_t restored_ns = engine_.state().time_ns;
    history_.record(restored_ns, CommandInput{restored_ns, c}, engine_);
    applied = applyToEngine(c);
    replaying_ = true;
    for (const FilterInput& item : replay_) process(timeOf(item), item);
    replaying_ = false;
    spdlog::warn("command {}: filter restored to {:.3f} s (onset {:.3f} s), {} inputs re-processed",
                 c.command_id(), 1e-9 * static_cast<double>(restored_ns),
                 1e-9 * static_cast<double>(c.onset_time_gps_ns()), replay_.size());
  } else {
    history_.record(engine_.state().time_ns, CommandInput{engine_.state().time_ns, c}, engine_);
    applied = applyToEngine(c);
    why = "not available in the configured mode";
  }
  countCommand(applied, reason);
  if (applied) {
    spdlog::info("command {} from '{}' applied (kind {})", c.command_id(), c.issuer(),
                 static_cast<int>(c.kind()));
  } else {
    spdlog::warn("command {} from '{}' refused: kind {}: {}", c.command_id(), c.issuer(),
                 static_cast<int>(c.kind()), why);
  }
}

core::SatelliteScope toCore(navbus::SatelliteScope s) {
  switch (s) {
    case navbus::SCOPE_PSEUDORANGE:
      return core::SatelliteScope::kRange;
    case navbus::SCOPE_PSEUDORANGE_RATE:
      return core::SatelliteScope::kRate;
    default:
      return core::SatelliteScope::kAll;
  }
}

std::int64_t FilterPipeline::restorePoint(const navbus::FilterCommand& c) const {
  // The onset is an estimate: a satellite is excluded from a margin before it (using one
  // satellite fewer for a few seconds costs little); a bias is compensated from the onset
  // itself (earlier would add the bias where there was none).
  const auto onset = static_cast<std::int64_t>(c.onset_time_gps_ns());
  return c.kind() == navbus::CMD_EXCLUDE_SATELLITE ? onset - config_.recovery_onset_margin_ns
                                                   : onset;
}

bool FilterPipeline::recoversFromOnset(const navbus::FilterCommand& c) const {
  return history_.enabled() && c.onset_time_gps_ns() > 0 &&
         (c.kind() == navbus::CMD_EXCLUDE_SATELLITE || c.kind() == navbus::CMD_COMPENSATE_BIAS ||
          c.kind() == navbus::CMD_RELEARN_BIAS || c.kind() == navbus::CMD_FAIL_SENSOR_AXIS);
}

std::optional<std::string> FilterPipeline::checkCommand(const navbus::FilterCommand& c) const {
  switch (c.kind()) {
    case navbus::CMD_EXCLUDE_SATELLITE:
    case navbus::CMD_READMIT_SATELLITE:
      if (c.sv_id() < 1 || c.sv_id() > 32) return fmt::format("sv_id {} outside 1..32", c.sv_id());
      return std::nullopt;
    case navbus::CMD_FAIL_SENSOR_AXIS:
    case navbus::CMD_RESTORE_SENSOR_AXIS:
      if (c.sensor() != navbus::SOURCE_ACCELEROMETER && c.sensor() != navbus::SOURCE_GYRO)
        return fmt::format("sensor {} is not an accelerometer or gyro",
                           static_cast<int>(c.sensor()));
      if (c.axis() > 2) return fmt::format("axis {} outside 0..2", c.axis());
      return std::nullopt;
    case navbus::CMD_COMPENSATE_BIAS:
    case navbus::CMD_RELEARN_BIAS: {
      if (c.sensor() != navbus::SOURCE_ACCELEROMETER && c.sensor() != navbus::SOURCE_GYRO)
        return fmt::format("sensor {} is not an accelerometer or gyro",
                           static_cast<int>(c.sensor()));
      if (c.axis() > 2) return fmt::format("axis {} outside 0..2", c.axis());
      const bool accel = c.sensor() == navbus::SOURCE_ACCELEROMETER;
      const double limit = compensationLimit(accel);
      // A re-learned bias is unknown up to bias_sigma; one beyond the limit is re-learned up to
      // the limit (relearnSigma), the largest bias the filter is configured to take.
      const bool relearn = c.kind() == navbus::CMD_RELEARN_BIAS;
      if (!std::isfinite(c.bias_sigma()) || c.bias_sigma() < 0.0 ||
          (c.bias_sigma() > limit && !relearn))
        return fmt::format("bias_sigma {} outside 0..{}", c.bias_sigma(), limit);
      if (!std::isfinite(c.bias()) || std::abs(c.bias()) > limit)
        return fmt::format(
            "bias {} outside +-{} ({})", c.bias(), limit,
            accel ? "m/s^2, max_accel_compensation_mg" : "rad/s, max_gyro_compensation_deg_per_h");
      return std::nullopt;
    }
    default:
      return std::nullopt;
  }
}

double FilterPipeline::compensationLimit(bool accel) const {
  return accel ? config_.max_accel_compensation_mps2 : config_.max_gyro_compensation_radps;
}

double FilterPipeline::relearnSigma(const navbus::FilterCommand& c) {
  const double limit = compensationLimit(c.sensor() == navbus::SOURCE_ACCELEROMETER);
  if (c.bias_sigma() <= limit) return c.bias_sigma();
  ++relearn_sigmas_clamped_;
  spdlog::warn(
      "command {} from '{}': re-learn bias_sigma {} beyond the compensation limit {} (recovery."
      "max_{}_compensation): re-learned up to the limit; {} clamped so far",
      c.command_id(), c.issuer(), c.bias_sigma(), limit,
      c.sensor() == navbus::SOURCE_ACCELEROMETER ? "accel" : "gyro", relearn_sigmas_clamped_);
  return limit;
}

bool FilterPipeline::applyToEngine(const navbus::FilterCommand& c) {
  switch (c.kind()) {
    case navbus::CMD_EXCLUDE_SATELLITE:
      engine_.excludeSatellite(c.sv_id(), toCore(c.scope()));
      return true;
    case navbus::CMD_READMIT_SATELLITE:
      engine_.readmitSatellite(c.sv_id(), toCore(c.scope()));
      return true;
    case navbus::CMD_RELEARN_BIAS:
      engine_.relearnBias(c.sensor() == navbus::SOURCE_ACCELEROMETER, c.axis(), relearnSigma(c));
      return true;
    case navbus::CMD_COMPENSATE_BIAS:
      engine_.compensateBias(c.sensor() == navbus::SOURCE_ACCELEROMETER, c.axis(), c.bias(),
                             c.bias_sigma());
      return true;
    case navbus::CMD_FAIL_SENSOR_AXIS:
      engine_.failSensorAxis(c.sensor() == navbus::SOURCE_ACCELEROMETER, c.axis());
      return true;
    case navbus::CMD_RESTORE_SENSOR_AXIS:
      engine_.restoreSensorAxis(c.sensor() == navbus::SOURCE_ACCELEROMETER, c.axis());
      return true;
    case navbus::CMD_SELECT_FUSION:
      switch (c.fusion()) {
        case navbus::FUSION_CENTRALIZED:
          return engine_.selectFusion(core::FusionStructure::kCentralized);
        case navbus::FUSION_FEDERATED:
          return engine_.selectFusion(core::FusionStructure::kFederated);
        case navbus::FUSION_ADAPTIVE:
          return engine_.selectFusion(core::FusionStructure::kAdaptive);
        default:
          return config_.engine.aiding == core::AidingMode::kInertialOnly;
      }
    case navbus::CMD_SELECT_MODE:
      // The aiding mode follows the configured inputs; only the current one is accepted.
      return c.mode() == toIdl(engine_.mode());
    case navbus::CMD_RESET:
      engine_.reset();
      return true;
    default:
      return false;
  }
}

std::string FilterPipeline::alignmentSummary() const {
  static const char* const phases[] = {"waiting for a GNSS position", "waiting for rest",
                                       "levelled, waiting for the GNSS course", "aligned"};
  static const char* const attitude[] = {"none", "star tracker", "gyrocompassing", "GNSS course"};
  static const char* const position[] = {"none", "GNSS fix", "pseudoranges"};
  std::ostringstream out;
  out << "alignment: " << phases[static_cast<int>(engine_.alignmentPhase())] << " after "
      << engine_.counters().imu_aligning << " increments";
  if (engine_.alignmentPhase() == core::AlignmentPhase::kAligned) {
    const core::AlignedStart& s = engine_.alignedStart();
    out << " (attitude from " << attitude[static_cast<int>(s.attitude_source)] << ", position from "
        << position[static_cast<int>(s.position_source)] << "; 1-sigma tilt "
        << s.att_sigma_ned_rad.x() * 1e3 << " mrad, heading " << s.att_sigma_ned_rad.z() * 1e3
        << " mrad; gyrocompassing would reach " << s.gyrocompass_heading_sigma_rad * 1e3
        << " mrad)";
  }
  if (engine_.alignmentFailedSolutions() > 0)
    out << ", pseudorange solutions failed " << engine_.alignmentFailedSolutions();
  if (engine_.counters().course_heading_checks > 0)
    out << ", heading measured again from the GNSS course "
        << engine_.counters().course_heading_checks << " time(s)";
  return out.str();
}

std::string FilterPipeline::summary() const {
  const core::EngineCounters& n = engine_.counters();
  std::ostringstream out;
  out << "increments integrated " << n.imu_used << " refused by the engine " << n.imu_refused
      << ", solutions published " << solution_seq_ << ", inertial gaps " << n.imu_gaps
      << ", GNSS epochs fused " << n.gnss_epochs_fused << ", fixes fused " << n.fixes_fused
      << ", star-tracker attitudes fused " << n.star_fused << ", ZUPTs " << n.zero_velocity_updates
      << ", NHC updates " << n.nonholonomic_updates << ", rows gated " << n.rows_gated
      << ", stage switches " << n.stage_switches << ", decisions seen " << decisions_seen_
      << ", commands applied " << commands_applied_ << " refused " << commands_refused_
      << " (unauthorized issuer " << commands_unauthorized_ << ", issuer not the writer's identity "
      << commands_impersonated_ << ", stale " << commands_stale_ << ") late " << commands_late_
      << ", re-learn sigmas clamped to the compensation limit " << relearn_sigmas_clamped_
      << ", sequencer timeouts " << sequencer_.timeouts() << ", pending " << sequencer_.pending()
      << ", recoveries from onset " << history_.rollbacks() << " (onset beyond history "
      << history_.outOfReach() << ")";
  if (monitor_losses_ > 0) {
    out << ", fault monitor found not alive " << monitor_losses_ << " time(s)"
        << (monitor_flags_ != 0 ? " (still not)" : "");
  }
  if (config_.engine.start == core::StartSource::kAligned) out << ", " << alignmentSummary();
  if (config_.engine.integrity.enabled) {
    out << ", protection-level epochs " << engine_.protectionLevelEpochs() << " refused "
        << engine_.protectionLevelEpochsRefused();
  }
  if (config_.low_latency_output) {
    const core::OutputPredictorCounters& l = predictor_.counters();
    out << ", low-latency outputs " << l.outputs << " (increments not after the anchor "
        << l.before_anchor << ", out of order " << l.not_after_previous << ", gaps " << l.gaps
        << ", beyond the buffer " << l.overflow << ")";
  }
  if (new_runs_ > 0) {
    out << ", new runs after a source restart " << new_runs_ << " (before the latest: solutions "
        << solutions_earlier_runs_ << ", increments " << increments_earlier_runs_ << ")";
  }
  return out.str();
}

}  // namespace navbus::nav_filter
