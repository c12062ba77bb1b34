#include "filter_node.hpp"

#include <chrono>

#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

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
                    bus::topic::kFilterDiagnostics, bus::profile::kDiagnosticsWriter)
              : bus::Writer<navbus::FilterDiagnostics>()),
      pipeline_(
          config, p.health(),
          {[this](const navbus::NavigationSolution& s) { solution_writer_.write(s); },
           publishesDiagnostics(config)
               ? std::function<void(const navbus::FilterDiagnostics&)>(
                     [this](const navbus::FilterDiagnostics& d) { diagnostics_writer_.write(d); })
               : nullptr}) {
  using namespace bus;
  p.subscribe<navbus::ImuIncrementPubSubType>(
      topic::kImuIncrement, profile::kSensorReader,
      [this](const auto& m, const auto&) { pipeline_.onImu(m); });
  p.subscribe<navbus::GnssObservationEpochPubSubType>(
      topic::kGnssObservations, profile::kMeasurementReader,
      [this](const auto& m, const auto&) { pipeline_.onGnssObservations(m); });
  p.subscribe<navbus::GnssFixPubSubType>(
      topic::kGnssFix, profile::kMeasurementReader,
      [this](const auto& m, const auto&) { pipeline_.onGnssFix(m); });
  p.subscribe<navbus::StarTrackerAttitudePubSubType>(
      topic::kStarTracker, profile::kMeasurementReader,
      [this](const auto& m, const auto&) { pipeline_.onStarTracker(m); });
  p.subscribe<navbus::FaultDecisionPubSubType>(topic::kFaultDecision, profile::kDecisionReader,
                                               [this](const auto& d, const auto&) {
                                                 pipeline_.onDecision(d);
                                                 updateState();
                                               });
  p.subscribe<navbus::FilterCommandPubSubType>(
      topic::kFilterCommand, profile::kDecisionReader, [this](const auto& c, const auto& info) {
        pipeline_.onCommand(c, participant_.dds().writerIdentity(info));
      });
  // Bounded-wait release of inputs held for a silent stream, and the held solution while
  // inertial data is lost (the solution topic's deadline promises at least 1 Hz).
  p.setAfterDispatch([this] { pump(); });
  p.addTimer(std::chrono::milliseconds(20), [this] { pump(); });
  p.addTimer(std::chrono::nanoseconds(config.engine.solution_period_ns),
             [this] { pipeline_.publishHeldSolution(); });
  updateState();
}

void FilterNode::pump() {
  pipeline_.pump(steadyNowNs());
}

void FilterNode::updateState() {
  participant_.setState(pipeline_.degraded() ? navbus::STATE_DEGRADED : navbus::STATE_RUNNING);
}

}  // namespace navbus::nav_filter
