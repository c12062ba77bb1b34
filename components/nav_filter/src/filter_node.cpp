#include "navbus/nav_filter/filter_node.hpp"

#include <algorithm>
#include <chrono>

#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/HealthPubSubTypes.h>

#include <spdlog/spdlog.h>

#include "navbus/bus/topics.hpp"

namespace navbus::nav_filter {

namespace {

std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

bool publishesDiagnostics(const FilterConfig& c) {
  return c.engine.aiding == core::AidingMode::kTightlyCoupled;
}

}  // namespace

FilterNode::FilterNode(bus::Participant& p, const FilterConfig& config)
    : participant_(p),
      solution_writer_(p.createWriter<navbus::NavigationSolutionPubSubType>(
          bus::topic::kNavSolution, config.solution_writer_profile)),
      diagnostics_writer_(
          publishesDiagnostics(config)
              ? p.createWriter<navbus::FilterDiagnosticsPubSubType>(
                    bus::topic::kFilterDiagnostics, config.diagnostics_writer_profile)
              : bus::Writer<navbus::FilterDiagnostics>()),
      low_latency_writer_(
          config.low_latency_output
              ? p.createWriter<navbus::NavigationSolutionPubSubType>(
                    bus::topic::kNavSolutionLowLatency, bus::profile::kLowLatencySolutionWriter)
              : bus::Writer<navbus::NavigationSolution>()),
      outcome_writer_(p.createWriter<navbus::FilterCommandOutcomePubSubType>(
          bus::topic::kCommandOutcome, bus::profile::kDecisionWriter)),
      lane_writer_(config.lanes.units.empty()
                       ? bus::Writer<navbus::LaneSolution>()
                       : p.createWriter<navbus::LaneSolutionPubSubType>(
                             bus::topic::kLaneSolution, config.solution_writer_profile)),
      pipeline_(
          config, p.health(),
          {{[this](const navbus::NavigationSolution& s) {
              if (!solution_writer_.write(s)) return;
              const bool first = last_solution_ns_ < 0;
              last_solution_ns_ = steadyNowNs();
              if (first) updateState();  // health says RUNNING at once
            },
            publishesDiagnostics(config)
                ? std::function<void(const navbus::FilterDiagnostics&)>(
                      [this](const navbus::FilterDiagnostics& d) { diagnostics_writer_.write(d); })
                : nullptr,
            [this](const navbus::NavigationSolution& s) { low_latency_writer_.write(s); },
            [this](const navbus::FilterCommandOutcome& o) { outcome_writer_.write(o); }},
           config.lanes.units.empty()
               ? std::function<void(const navbus::LaneSolution&)>()
               : [this](const navbus::LaneSolution& l) { lane_writer_.write(l); }}),
      not_producing_ns_(
          std::max(kNotProducingMinNs, kNotProducingPeriods * config.engine.solution_period_ns)),
      sensors_(p, sensorEvents()) {
  using namespace bus;
  p.subscribe<navbus::FaultDecisionPubSubType>(topic::kFaultDecision, profile::kDecisionReader,
                                               [this](const auto& d, const auto&) {
                                                 pipeline_.onDecision(d);
                                                 updateState();
                                               });
  p.subscribe<navbus::FilterCommandPubSubType>(
      topic::kFilterCommand, profile::kDecisionReader, [this](const auto& c, const auto& info) {
        pipeline_.onCommand(c, participant_.dds().writerIdentity(info));
      });
  auto* progress_reader = p.subscribe<navbus::FaultMonitorProgressPubSubType>(
      topic::kFaultProgress, profile::kProgressReader,
      [this](const auto& report, const auto& info) {
        pipeline_.onFaultMonitorProgress(report);
        // Judging is proof of life too: a monitor busy with a burst of diagnostics (a replay
        // as fast as the readers take it) may send its 1-Hz health late, and a filter that
        // then believed it dead stopped waiting for its judgements (bus != offline).
        if (monitor_ && monitor_identity_) {
          const std::optional<std::string> writer = participant_.dds().writerIdentity(info);
          if (!writer || *writer == *monitor_identity_) monitor_->onReport(steadyNowNs());
        }
      });
  if (config.fault_monitor && config.fault_monitor->judged_from_start)
    awaitFaultMonitor(config.fault_monitor->judgement_wait_ns, *progress_reader,
                      publishesDiagnostics(config));
  subscribeInputs();
  // Bounded-wait release of inputs held for a silent stream, and the held solution while
  // inertial data is lost (the solution topic's deadline promises at least 1 Hz).
  p.setAfterDispatch([this] { pump(); });
  if (config.fault_monitor) watchFaultMonitor(*config.fault_monitor);
  p.addTimer(std::chrono::nanoseconds(bus::StallDetector::kLoopPeriodNs), [this] {
    if (monitor_) pipeline_.setFaultMonitorAlive(monitor_->alive(steadyNowNs()));
    pump();
    updateState();
  });
  p.addTimer(std::chrono::nanoseconds(config.engine.solution_period_ns),
             [this] { pipeline_.publishHeldSolution(); });
  updateState();
}

void FilterNode::subscribeInputs() {
  using namespace bus;
  sensors_.subscribe<navbus::ImuIncrement>(profile::kSensorReader,
                                           [this](const auto& m) { pipeline_.onImu(m); });
  sensors_.subscribe<navbus::ImuIncrementBlock>(profile::kSensorReader,
                                                [this](const auto& m) { pipeline_.onImuBlock(m); });
  sensors_.subscribe<navbus::GnssObservationEpoch>(
      profile::kMeasurementReader, [this](const auto& m) { pipeline_.onGnssObservations(m); });
  sensors_.subscribe<navbus::GnssFix>(profile::kMeasurementReader,
                                      [this](const auto& m) { pipeline_.onGnssFix(m); });
  sensors_.subscribe<navbus::StarTrackerAttitude>(
      profile::kMeasurementReader, [this](const auto& m) { pipeline_.onStarTracker(m); });
  // Fast pacing's blocks: each element is taken as one sample of its own topic.
  sensors_.subscribe<navbus::GnssObservationEpochBlock>(
      profile::kMeasurementReader, [this](const auto& m) { pipeline_.onGnssObservationsBlock(m); });
  sensors_.subscribe<navbus::GnssFixBlock>(profile::kMeasurementReader,
                                           [this](const auto& m) { pipeline_.onGnssFixBlock(m); });
  sensors_.subscribe<navbus::StarTrackerAttitudeBlock>(
      profile::kMeasurementReader, [this](const auto& m) { pipeline_.onStarTrackerBlock(m); });
}

bool FilterNode::faultMonitorConnected(eprosima::fastdds::dds::DataReader& progress_reader,
                                       bool diagnostics) const {
  eprosima::fastdds::dds::SubscriptionMatchedStatus progress;
  progress_reader.get_subscription_matched_status(progress);
  return progress.current_count > 0 && (!diagnostics || diagnostics_writer_.matchedReaders() > 0);
}

void FilterNode::awaitFaultMonitor(std::int64_t wait_ns,
                                   eprosima::fastdds::dds::DataReader& progress_reader,
                                   bool diagnostics) {
  const auto start = std::chrono::steady_clock::now();
  const auto until = start + std::chrono::nanoseconds(wait_ns);
  // Meanwhile the loop runs (health says STARTING, commands are taken), without inputs.
  participant_.setState(navbus::STATE_STARTING);
  while (!participant_.stopping() && !faultMonitorConnected(progress_reader, diagnostics) &&
         std::chrono::steady_clock::now() < until) {
    participant_.spinOnce(kMonitorPollPeriod);
  }
  const double waited_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (faultMonitorConnected(progress_reader, diagnostics)) {
    spdlog::info("fault monitor connected after {:.2f} s: taking the inputs (judged_from_start)",
                 waited_s);
  } else if (!participant_.stopping()) {
    spdlog::warn(
        "no fault monitor connected after {:.2f} s (fault_monitor.judgement_wait_s): taking the "
        "inputs without it; epochs published before it connects are not judged",
        waited_s);
  }
}

bus::SensorReaders::Events FilterNode::sensorEvents() {
  bus::SensorReaders::Events events;
  events.ended = [this](bus::StreamKind kind, std::uint32_t id, std::uint64_t) {
    pipeline_.onStreamEnded(kind, id);
    if (kind == bus::StreamKind::kImu && stop_after_end_ != nullptr) stop_after_end_->ended();
  };
  events.writers_alive = [this](bus::StreamKind kind, bool alive) {
    pipeline_.setWritersAlive(kind, alive, steadyNowNs());
    if (kind == bus::StreamKind::kImu && stop_after_end_ != nullptr)
      stop_after_end_->writersAlive(alive);
  };
  return events;
}

void FilterNode::watchFaultMonitor(const FaultMonitorWatch& watch) {
  monitor_.emplace(watch.timeout_ns, steadyNowNs());
  monitor_identity_ = watch.identity;
  bus::StreamCounters& counters = participant_.health().stream(bus::topic::kHealth);
  participant_.subscribe<navbus::HealthPubSubType>(
      bus::topic::kHealth, bus::profile::kHealthReader,
      [this, watch, &counters](const navbus::Health& h, const auto& info) {
        if (h.participant().to_string() != watch.participant) return;  // not the monitor
        const std::optional<std::string> writer = participant_.dds().writerIdentity(info);
        if (writer && *writer != watch.identity) {
          // Under DDS Security, a report in the monitor's name by another identity.
          if (++counters.rejected[navbus::REJECT_UNAUTHORIZED] == 1)
            spdlog::warn("{}: a report as '{}' written by '{}', not '{}': ignored",
                         bus::topic::kHealth, watch.participant, *writer, watch.identity);
          return;
        }
        ++counters.accepted;
        monitor_->onReport(steadyNowNs());
      });
}

void FilterNode::pump() {
  const std::int64_t now = steadyNowNs();
  // The pump runs after every reader dispatch and at least every loop period.
  if (const auto stalled = stalls_.running(now)) pipeline_.resumedAfterStall(now, *stalled);
  pipeline_.pump(now);
}

void FilterNode::updateState() {
  if (last_solution_ns_ < 0) {
    participant_.setState(navbus::STATE_STARTING);
    return;
  }
  const bool producing = steadyNowNs() - last_solution_ns_ <= not_producing_ns_;
  participant_.setState(pipeline_.degraded() || !producing ? navbus::STATE_DEGRADED
                                                           : navbus::STATE_RUNNING);
}

}  // namespace navbus::nav_filter
