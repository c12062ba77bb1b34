#include "navbus/fault_manager/fault_pipeline.hpp"

#include <algorithm>
#include <sstream>

#include <spdlog/spdlog.h>

#include "navbus/bus/streams.hpp"
#include "navbus/bus/topics.hpp"

namespace navbus::fault_manager {

namespace {
constexpr const char* kIssuer = "fault-manager";  ///< FilterCommand.issuer of this participant
}  // namespace

FaultPipeline::FaultPipeline(const FaultManagerConfig& config, bus::HealthCounters& health,
                             Sinks sinks, std::uint64_t run_id)
    : config_(config),
      health_(health),
      sinks_(std::move(sinks)),
      glr_(config.glr),
      diagnostics_gate_(bus::topic::kFilterDiagnostics,
                        health.stream(bus::topic::kFilterDiagnostics)),
      run_id_(run_id),
      outcomes_(kIssuer, run_id) {
  if (config.dither.enabled) dither_.emplace(config.dither);
  if (config.parity.enabled) parity_.emplace(config.parity);
  if (config.receivers.enabled) receivers_.emplace(config.receivers);
}

void FaultPipeline::onRawBlock(const navbus::ImuRawBlock& block) {
  if (dither_) dither_->onRawBlock(block, *this);
}

void FaultPipeline::onImuIncrement(const navbus::ImuIncrement& increment) {
  if (!parity_) return;
  parity_->onIncrement(increment, *this);
  if (parity_->counters().new_runs != parity_runs_) {
    parity_runs_ = parity_->counters().new_runs;  // a new run's times start over
    parity_reported_ = -1;
  }
  // How far the units' data is judged, every kParityReportPeriodNs of it (after its commands).
  const std::int64_t tested = parity_->testedUpToNs();
  if (tested < 0 || tested / kParityReportPeriodNs == parity_reported_ / kParityReportPeriodNs)
    return;
  // With the GLR, the first report is its first judgement: a report that judged no diagnostics
  // yet would tell the filter its diagnostics are unjudged (its solutions then say no monitor).
  if (config_.glr.enabled && judged_.time_gps_ns() == 0) return;
  parity_reported_ = tested;
  reportProgress(judged_);
}

void FaultPipeline::onLaneSolution(const navbus::LaneSolution& lane) {
  if (!parity_ || lane.vehicle_id() != config_.vehicle_id) return;
  parity_->onLaneSolution(lane, *this);
}

void FaultPipeline::onGnssEpoch(const navbus::GnssObservationEpoch& epoch) {
  if (!receivers_) return;
  receivers_->onEpoch(epoch, *this);
  reportReceiversProgress();
}

void FaultPipeline::receiverGone(StreamKind kind, std::uint32_t sensor_id,
                                 std::uint64_t last_time_gps_ns) {
  if (!receivers_ || kind != StreamKind::kGnssObservations) return;
  receivers_->receiverGone(sensor_id, static_cast<std::int64_t>(last_time_gps_ns), *this);
  reportReceiversProgress();
}

void FaultPipeline::reportReceiversProgress() {
  // How far the receivers' epochs are judged, after every time tested (after its commands).
  const std::int64_t tested = receivers_->testedUpToNs();
  if (tested <= receivers_reported_) return;
  if (config_.glr.enabled && judged_.time_gps_ns() == 0) return;  // as the parity test's
  receivers_reported_ = tested;
  reportProgress(judged_);
}

void FaultPipeline::onStreamSample(StreamKind kind, std::uint32_t sensor_id, std::uint64_t seq,
                                   std::uint64_t time_gps_ns, std::int64_t wall_now_ns,
                                   const StreamWatchdog::Source& source) {
  // Best-effort watchdog readers may lose samples: count them from the sequence numbers. A
  // restarted writer (time going back) starts a new count.
  auto& tracker = trackers_[kind];
  auto o = tracker.check(sensor_id, seq, time_gps_ns);
  if (o.rejection) {
    tracker.reset(sensor_id);
    o = tracker.check(sensor_id, seq, time_gps_ns);
  }
  // Observed, not validated: a monitor.
  health_.stream(bus::streamInfo(kind).topic).countAccepted(sensor_id, o.missing);
  if (auto e = watchdog_.onSample({kind, sensor_id}, time_gps_ns, wall_now_ns, source))
    onWatchdogEvent(*e);
}

void FaultPipeline::onDeadlineMissed(StreamKind kind, std::uint32_t sensor_id,
                                     std::int64_t wall_now_ns) {
  const auto deadline_ns = static_cast<std::int64_t>(deadline_s_[kind] * 1e9);
  if (auto e = watchdog_.onDeadlineMissed({kind, sensor_id}, wall_now_ns, deadline_ns))
    onWatchdogEvent(*e);
}

void FaultPipeline::onWatchdogTick(std::int64_t wall_now_ns) {
  for (const auto& e : watchdog_.onTick(wall_now_ns)) onWatchdogEvent(e);
}

void FaultPipeline::onWritersGone(StreamKind kind, std::int64_t wall_now_ns) {
  for (const auto& e : watchdog_.onWritersGone(kind, wall_now_ns)) onWatchdogEvent(e);
}

void FaultPipeline::resumedAfterStall(std::int64_t wall_now_ns, std::int64_t stalled_ns) {
  watchdog_.resumedAfterStall(wall_now_ns);
  ++stalls_;
  longest_stall_ns_ = std::max(longest_stall_ns_, stalled_ns);
  spdlog::warn(
      "fault manager not running for {:.3f} s (stopped, starved of CPU): silences count "
      "from now, lost liveliness is believed if it is not back within {:.0f} s",
      1e-9 * static_cast<double>(stalled_ns),
      1e-9 * static_cast<double>(StreamWatchdog::kLivelinessGraceNs));
}

void FaultPipeline::onParityUnitEnded(std::uint32_t sensor_id) {
  if (!parity_ || !parity_->onUnitEnded(sensor_id)) return;
  // Every unit has delivered its last increment: all of their data is judged, also the last
  // part of a report period.
  const std::int64_t tested = parity_->testedUpToNs();
  if (tested <= parity_reported_) return;
  parity_reported_ = tested;
  reportProgress(judged_);
}

void FaultPipeline::onStreamEnded(StreamKind kind, std::uint32_t sensor_id,
                                  std::uint64_t end_time_gps_ns) {
  // An IMU's raw stream ends with its increment stream, at the same data time (the same
  // sensor; the raw reader does not see the raw writer's dispose with Fast DDS 2.9, see
  // docs/results.md). Raw blocks up to that time may still arrive after it: they are no new run.
  if (kind == StreamKind::kImu)
    onStreamEnded(StreamKind::kImuRaw, sensor_id,
                  std::max(end_time_gps_ns, watchdog_.lastTime({kind, sensor_id})));
  receiverGone(kind, sensor_id, end_time_gps_ns);  // the cross-receiver test: not waited for
  if (!watchdog_.onEnded({kind, sensor_id}, end_time_gps_ns)) return;
  trackers_[kind].reset(sensor_id);
  ++ended_;
  spdlog::info("{} stream {} ended as its writer announced: not a loss", bus::streamInfo(kind).name,
               sensor_id);
}

std::vector<StreamKey> FaultPipeline::onWriterParticipantEnded(
    const StreamWatchdog::WriterParticipant& writer) {
  const std::vector<StreamKey> keys = watchdog_.onParticipantEnded(writer);
  if (!keys.empty()) {
    spdlog::info(
        "a writer announced the end of all its data in its health report: {} of its "
        "streams end",
        keys.size());
  }
  for (const StreamKey& key : keys) onStreamEnded(key.kind, key.sensor_id, watchdog_.lastTime(key));
  return keys;
}

void FaultPipeline::onWatchdogEvent(const WatchdogEvent& e) {
  navbus::FaultDecision d;
  d.time_gps_ns(e.last_time_gps_ns);
  d.event(e.lost ? navbus::EVENT_STREAM_LOST : navbus::EVENT_STREAM_RESTORED);
  d.source(bus::streamInfo(e.key.kind).fault_source);
  d.sensor_id(e.key.sensor_id);
  d.shape(navbus::SHAPE_NONE);
  d.test_statistic(e.silence_s);
  d.threshold(deadline_s_[e.key.kind]);
  d.onset_time_gps_ns(e.last_time_gps_ns);
  d.detector("watchdog");
  const std::uint32_t id = decide(d);
  (e.lost ? lost_ : restored_)++;
  spdlog::warn("decision {}: {} stream {} {} (silent {:.3f} s)", id,
               bus::streamInfo(e.key.kind).name, e.key.sensor_id, e.lost ? "LOST" : "RESTORED",
               e.silence_s);
  navbus::FilterCommand c;
  c.kind(e.lost ? navbus::CMD_EXCLUDE_STREAM : navbus::CMD_READMIT_STREAM);
  c.decision_id(id);
  c.time_gps_ns(e.last_time_gps_ns);
  c.sensor(d.source());
  c.sensor_id(e.key.sensor_id);
  command(c);
  if (e.lost) receiverGone(e.key.kind, e.key.sensor_id, e.last_time_gps_ns);
}

void FaultPipeline::onSecondWriter(StreamKind kind, std::uint32_t sensor_id,
                                   std::uint64_t time_gps_ns) {
  navbus::FaultDecision d;
  d.time_gps_ns(time_gps_ns);
  d.event(navbus::EVENT_FAULT_DETECTED);
  d.source(bus::streamInfo(kind).fault_source);
  d.sensor_id(sensor_id);
  d.shape(navbus::SHAPE_NONE);
  d.test_statistic(2.0);  // writers publishing the sensor id
  d.threshold(1.0);       // writers allowed
  d.onset_time_gps_ns(time_gps_ns);
  d.detector("writer-identity");
  const std::uint32_t id = decide(d);
  ++second_writers_;
  spdlog::warn("decision {}: a second writer publishes {} stream {} while its owner is alive", id,
               bus::streamInfo(kind).name, sensor_id);
}

bool FaultPipeline::onDiagnostics(const navbus::FilterDiagnostics& msg) {
  if (msg.vehicle_id() != config_.vehicle_id) {
    ++other_vehicles_;
    return false;
  }
  if (!diagnostics_gate_.admit(msg, msg.vehicle_id(), msg.seq(), msg.time_gps_ns())) {
    reportProgress(msg);
    return false;
  }
  if (diagnostics_gate_.sourceRestarted()) {
    // The filter started a new run at an earlier time: its statistics start over too.
    glr_ = GlrDetector(config_.glr);
    ++filter_new_runs_;
  }
  const std::uint64_t before = glr_.counters().epochs;
  glr_.onDiagnostics(msg, *this);
  reportProgress(msg);
  return glr_.counters().epochs != before;
}

void FaultPipeline::reportProgress(const navbus::FilterDiagnostics& judged) {
  judged_ = judged;
  if (!sinks_.progress) return;
  navbus::FaultMonitorProgress p;
  p.vehicle_id(config_.vehicle_id);
  p.judged_up_to_gps_ns(judged.time_gps_ns());
  p.diagnostics_seq(judged.seq());
  p.last_command_id(next_command_id_ - 1);
  p.issuer(kIssuer);
  p.run_id(run_id_);
  p.imu_judged_up_to_gps_ns(
      static_cast<std::uint64_t>(std::max<std::int64_t>(parity_reported_, 0)));
  p.gnss_judged_up_to_gps_ns(static_cast<std::uint64_t>(
      receivers_ ? std::max<std::int64_t>(receivers_->testedUpToNs(), 0) : 0));
  sinks_.progress(p);
}

void FaultPipeline::satelliteKeptOut(int sv_id) {
  // The GLR's epochs lose it too: a filter fusing both receivers still monitors its rows.
  glr_.keepOut(sv_id);
}

std::uint32_t FaultPipeline::decide(navbus::FaultDecision& d) {
  d.decision_id(next_decision_id_++);
  d.run_id(run_id_);
  if (sinks_.decision) sinks_.decision(d);
  return d.decision_id();
}

void FaultPipeline::command(navbus::FilterCommand& c) {
  c.command_id(next_command_id_++);
  c.vehicle_id(config_.vehicle_id);
  c.issuer(kIssuer);
  c.run_id(run_id_);
  if (sinks_.command) sinks_.command(c);
}

void FaultPipeline::onCommandOutcome(const navbus::FilterCommandOutcome& o) {
  if (!outcomes_.onOutcome(o) || o.outcome() == navbus::OUTCOME_APPLIED) return;
  if (CommandOutcomes::notItsStream(o)) {
    spdlog::info("command {} (kind {}): the filter does not fuse that stream ({})", o.command_id(),
                 static_cast<int>(o.kind()), o.detail());
    return;
  }
  spdlog::warn("command {} (kind {}) {} by the filter: {}{}", o.command_id(),
               static_cast<int>(o.kind()),
               o.outcome() == navbus::OUTCOME_CLAMPED ? "clamped" : "refused", o.detail(),
               outcomes_.degraded() ? "; the fault loop is not closed (health DEGRADED)" : "");
}

std::string FaultPipeline::summary() const {
  std::ostringstream out;
  out << "decisions published " << decisions() << " (stream lost " << lost_ << ", restored "
      << restored_ << ", second writers " << second_writers_
      << ", deadline events not confirmed by the silence " << watchdog_.unconfirmedDeadlines()
      << ", of streams paced ahead of real time " << watchdog_.deadlinesAheadOfRealTime()
      << "), streams paced ahead of real time " << watchdog_.streamsAheadOfRealTime()
      << " (judged by their writers only), liveliness losses after a stall that were stale "
      << watchdog_.staleLivelinessEvents() << ", streams ended as announced " << ended_
      << ", commands published " << commands() << " (the filter applied " << outcomes_.applied()
      << ", clamped " << outcomes_.clamped() << ", refused " << outcomes_.refused();
  if (outcomes_.notItsStreams() > 0)
    out << " (streams it does not fuse: " << outcomes_.notItsStreams() << ")";
  out << "); " << glr_.summary();
  if (dither_) out << "; " << dither_->summary();
  if (parity_) out << "; " << parity_->summary();
  if (receivers_) out << "; " << receivers_->summary();
  if (stalls_ > 0)
    out << "; stalls of the fault manager process " << stalls_ << " (longest "
        << 1e-9 * static_cast<double>(longest_stall_ns_) << " s)";
  if (filter_new_runs_ > 0)
    out << "; GLR restarted with the filter's new runs " << filter_new_runs_;
  if (other_vehicles_ > 0) out << "; diagnostics of other vehicles ignored " << other_vehicles_;
  return out.str();
}

}  // namespace navbus::fault_manager
