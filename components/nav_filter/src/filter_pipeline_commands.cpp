// FilterPipeline's fault-management inputs (filter_pipeline.hpp): decisions (counted),
// commands (checked, ordered, merged late by rewinding, restored to before a fault's onset),
// the fault manager's progress reports, stream declarations and writer liveliness.
#include <spdlog/spdlog.h>

#include "navbus/nav_filter/engine_commands.hpp"
#include "navbus/nav_filter/filter_pipeline.hpp"

namespace navbus::nav_filter {

bool FilterPipeline::countRecovery(bool restored) {
  ++(restored ? counters_.onset_recoveries : counters_.onset_beyond_history);
  return restored;
}

void FilterPipeline::onDecision(const navbus::FaultDecision& d) {
  // Decisions are facts (idl/Fault.idl): the filter acts on commands only. It counts what it
  // saw so that the summary shows decisions that came without a command.
  ++counters_.decisions_seen;
  spdlog::info("decision {} ({}): event {} source {} sv {} axis {} statistic {:.4g} / {:.4g}",
               d.decision_id(), d.detector(), static_cast<int>(d.event()),
               static_cast<int>(d.source()), d.sv_id(), d.axis(), d.test_statistic(),
               d.threshold());
}

bool FilterPipeline::applyStreamCommand(const navbus::FilterCommand& c) {
  auto idOf = [](const std::optional<InputConfig>& input) {
    return input ? std::optional<std::uint32_t>(input->id) : std::nullopt;
  };
  const std::optional<std::uint32_t> flag = SolutionFlags::streamFlag(
      c, {config_.imu.id, idOf(config_.gnss_observations), idOf(config_.gnss_fix),
          idOf(config_.star_tracker), config_.second_gnss_receiver_id});
  if (!flag) return false;
  flags_.applyStreamCommand(c, *flag);
  if (c.kind() == navbus::CMD_EXCLUDE_STREAM && *flag == navbus::FAULT_IMU_STREAM_LOST) {
    if (imu_writers_since_ns_ == kWritersUnknown)
      setImuLost();  // offline: nothing tells whether a writer lives
    else             // a stalled or starved process between them: the data may still come
      spdlog::warn("IMU declared lost: flagged; the merge waits until its writer is gone");
  }
  publishHeldSolution();
  return true;
}

std::optional<std::string> FilterPipeline::endedAsAnnounced(const navbus::FilterCommand& c) const {
  // The fault manager watches with best-effort readers, which may miss a writer's dispose;
  // this filter's readers are reliable: a stream whose end it received is not lost.
  if (c.kind() != navbus::CMD_EXCLUDE_STREAM) return std::nullopt;
  for (const bus::StreamKindInfo& stream : bus::kStreamKinds) {
    if (stream.fault_source != c.sensor() || stream.merge_rank == bus::kNotMerged) continue;
    if (ended_streams_.count({stream.merge_rank, c.sensor_id()}) == 0) continue;
    return fmt::format("{} id {} ended as announced (its writer disposed it after its last sample)",
                       stream.topic, c.sensor_id());
  }
  return std::nullopt;
}

void FilterPipeline::setImuLost() {
  sequencer_.setActive({kRankImu, config_.imu.id}, false);
  engine_.markInertialLost();
}

void FilterPipeline::setWritersAlive(bus::StreamKind kind, bool alive, std::int64_t now_ns) {
  if (kind != bus::StreamKind::kImu) return;
  if (alive || imu_writers_since_ns_ < 0) imu_writers_since_ns_ = alive ? kWritersAlive : now_ns;
}

void FilterPipeline::checkImuWriters(std::int64_t now_ns) {
  if (imu_writers_since_ns_ < 0 || now_ns - imu_writers_since_ns_ < config_.sequencer_max_wait_ns)
    return;
  imu_writers_since_ns_ = kWritersUnknown;
  if ((flags_.flags() & navbus::FAULT_IMU_STREAM_LOST) == 0) return;
  setImuLost();
  publishHeldSolution();
}

void FilterPipeline::onFaultMonitorProgress(const navbus::FaultMonitorProgress& report) {
  if (report.vehicle_id() != config_.vehicle_id) return;
  if (const auto judged = judgements_.onProgress(report)) noteJudged(*judged);
}

void FilterPipeline::noteJudged(std::int64_t judged_up_to_ns) {
  sequencer_.judged(kCommandStream, judged_up_to_ns);
  judged_up_to_ns_ = std::max(judged_up_to_ns_, judged_up_to_ns);
  // The IMU data's own judgement (setImuJudged): its report's imu_judged_up_to_gps_ns.
  if (owe_imu_judgement_ && judgements_.imuJudged() > 0)
    sequencer_.judged(kImuJudgementStream, judgements_.imuJudged());
  // The receivers' epochs' judgement, while the fused receiver's stream goes on (after its end
  // no epoch follows to be judged: the stream stays set aside), and only when it went further:
  // a judge whose wait ran out (a receiver silent, the fault manager stopped) is not waited for
  // again until it judges more.
  if (receivers_judged_ && judgements_.gnssJudged() > gnss_judged_passed_ns_ &&
      !fusedReceiverEnded()) {
    gnss_judged_passed_ns_ = judgements_.gnssJudged();
    sequencer_.judged(kGnssJudgementStream, gnss_judged_passed_ns_);
  }
}

void FilterPipeline::onCommand(const navbus::FilterCommand& c,
                               const std::optional<std::string>& writer_identity) {
  // Released by pump() only: the command below is queued before the judgement counts.
  if (const auto judged = judgements_.onCommand(c)) noteJudged(*judged);
  if (!commands_.addressedToThisVehicle(c)) return;  // for another vehicle: not ours
  if (!commands_.authorized(c, writer_identity)) return;
  if (c.kind() == navbus::CMD_EXCLUDE_STREAM || c.kind() == navbus::CMD_READMIT_STREAM) {
    // About the merge itself (a lost stream must stop holding it): at once.
    if (commands_.refuseIfStale(c, first_input_ns_)) return;
    if (const auto ended = endedAsAnnounced(c)) {
      commands_.report(c, false, navbus::REJECT_NOT_APPLICABLE, *ended);
      spdlog::warn("command {} from '{}' refused: {}", c.command_id(), c.issuer(), *ended);
      return;
    }
    const bool applied = applyStreamCommand(c);
    commands_.report(c, applied, navbus::REJECT_UNEXPECTED_SOURCE,
                     applied ? std::string() : "not a stream of this filter");
    if (!applied)
      spdlog::warn(
          "command {} from '{}' refused: stream source {} id {} is not a stream of this "
          "filter",
          c.command_id(), c.issuer(), static_cast<int>(c.sensor()), c.sensor_id());
    return;
  }
  enterCommand(c);
}

void FilterPipeline::addOwnCommand(const navbus::FilterCommand& c) {
  enterCommand(c);
}

void FilterPipeline::enterCommand(const navbus::FilterCommand& c) {
  const auto time_ns = static_cast<std::int64_t>(c.time_gps_ns());
  if (time_ns > 0) {
    FilterInput input = CommandInput{time_ns, c};
    if (!sequencer_.late(kCommandStream, time_ns)) {
      sequencer_.push(kCommandStream, time_ns, std::move(input));
      return;  // takes effect in order, at its data time
    }
    commands_.countLate();
    // Merged in its place by rewinding, as a late sample is; beyond the history, at once.
    if (mergeLate(kCommandStream, time_ns, input)) return;
  }
  executeCommand(c);
}

void FilterPipeline::executeCommand(const navbus::FilterCommand& c) {
  if (commands_.refuseIfStale(c, first_input_ns_)) return;
  std::string why;
  bool applied = false;
  navbus::RejectReason reason = navbus::REJECT_NOT_APPLICABLE;
  if (auto refusal = commands_.check(c)) {
    why = *refusal;
    reason = navbus::REJECT_OUT_OF_RANGE;
  } else if (history_.enabled() && answersFaultWithOnset(c) &&
             countRecovery(history_.rollback(restorePoint(c, config_.recovery_onset_margin_ns),
                                             engine_, replay_))) {
    applied = applyFromRestorePoint(c);
  } else {
    const std::int64_t now_ns = engine_.state().time_ns;
    history_.record(now_ns, {kCommandStream, now_ns, CommandInput{now_ns, c}}, engine_);
    applied = applyToEngine(c);
    why = "not available in the configured mode";
  }
  commands_.report(c, applied, reason, why);
  if (applied) {
    spdlog::info("command {} from '{}' applied (kind {})", c.command_id(), c.issuer(),
                 static_cast<int>(c.kind()));
  } else {
    spdlog::warn("command {} from '{}' refused: kind {}: {}", c.command_id(), c.issuer(),
                 static_cast<int>(c.kind()), why);
  }
}

bool FilterPipeline::applyFromRestorePoint(const navbus::FilterCommand& c) {
  // Restored to the snapshot before the restore point: what came before the point is
  // re-processed as it was, the command applies at the point, and what followed is re-processed
  // without the fault (nothing is published meanwhile: those solutions went out). The result
  // is the same whatever the snapshot period (it only sets how much is re-processed).
  const std::int64_t snapshot_ns = engine_.state().time_ns;
  const std::int64_t point_ns = restorePoint(c, config_.recovery_onset_margin_ns);
  replaying_ = true;
  std::size_t next = 0;
  for (; next < replay_.size() && replay_[next].time_ns < point_ns; ++next) {
    MergedInput& item = replay_[next];
    process(item.stream, item.time_ns, std::move(item.input));
  }
  history_.record(point_ns, {kRestoredCommandStream, point_ns, CommandInput{point_ns, c}}, engine_);
  const bool applied = applyToEngine(c);
  for (std::size_t k = next; k < replay_.size(); ++k) {
    MergedInput& item = replay_[k];
    process(item.stream, item.time_ns, std::move(item.input));
  }
  replaying_ = false;
  spdlog::warn(
      "command {}: filter restored to {:.3f} s, applied at {:.3f} s (onset {:.3f} s), {} inputs "
      "re-processed",
      c.command_id(), 1e-9 * static_cast<double>(snapshot_ns), 1e-9 * static_cast<double>(point_ns),
      1e-9 * static_cast<double>(c.onset_time_gps_ns()), replay_.size());
  return applied;
}

bool FilterPipeline::applyToEngine(const navbus::FilterCommand& c) {
  const double relearn_sigma =
      c.kind() == navbus::CMD_RELEARN_BIAS ? commands_.relearnSigma(c) : 0.0;
  return applyEngineCommand(engine_, c, relearn_sigma, receiverIndex(c.sensor_id()));
}
}  // namespace navbus::nav_filter
