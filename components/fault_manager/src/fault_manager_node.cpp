#include "navbus/fault_manager/fault_manager_node.hpp"

#include <chrono>
#include <type_traits>

#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "navbus/bus/topics.hpp"

namespace navbus::fault_manager {

namespace {
std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

FaultManagerNode::FaultManagerNode(bus::Participant& p, const FaultManagerConfig& config)
    : participant_(p),
      decision_writer_(p.createWriter<navbus::FaultDecisionPubSubType>(
          bus::topic::kFaultDecision, bus::profile::kDecisionWriter)),
      command_writer_(p.createWriter<navbus::FilterCommandPubSubType>(
          bus::topic::kFilterCommand, bus::profile::kDecisionWriter)),
      pipeline_(config, p.health(),
                {[this](const navbus::FaultDecision& d) { decision_writer_.write(d); },
                 [this](const navbus::FilterCommand& c) { command_writer_.write(c); }},
                bus::wallTimeNowNs()) {
  using namespace bus;
  watch<navbus::ImuIncrementPubSubType>(
      topic::kImuIncrement, profile::kSensorWatchdogReader, StreamKind::kImu,
      [](const auto& m) { return m.sensor_id(); }, [](const auto& m) { return m.time_gps_ns(); });
  // Fast pacing's blocks of increments: each element is watched as one increment.
  watch<navbus::ImuIncrementBlockPubSubType>(
      topic::kImuIncrementBlock, profile::kSensorWatchdogReader, StreamKind::kImu,
      [](const auto& m) { return m.sensor_id(); },
      [](const auto& m) {  // its newest increment's (the watchdog takes every element's)
        return m.increments().empty() ? std::uint64_t{0} : m.increments().back().time_gps_ns();
      });
  watch<navbus::ImuRawBlockPubSubType>(
      topic::kImuRaw, profile::kRawImuMonitorReader, StreamKind::kImuRaw,
      [](const auto& m) { return m.sensor_id(); },
      [](const auto& m) { return m.first_sample_time_gps_ns(); });
  watch<navbus::GnssObservationEpochPubSubType>(
      topic::kGnssObservations, profile::kMeasurementWatchdogReader, StreamKind::kGnssObservations,
      [](const auto& m) { return m.receiver_id(); }, [](const auto& m) { return m.time_gps_ns(); });
  watch<navbus::GnssFixPubSubType>(
      topic::kGnssFix, profile::kMeasurementWatchdogReader, StreamKind::kGnssFix,
      [](const auto& m) { return m.receiver_id(); }, [](const auto& m) { return m.time_gps_ns(); });
  watch<navbus::StarTrackerAttitudePubSubType>(
      topic::kStarTracker, profile::kMeasurementWatchdogReader, StreamKind::kStarTracker,
      [](const auto& m) { return m.tracker_id(); }, [](const auto& m) { return m.time_gps_ns(); });
  // Confirms suspect streams (a DDS deadline event before the own silence reached it) within
  // this period of their silence reaching the deadline.
  p.addTimer(std::chrono::milliseconds(10), [this] { pipeline_.onWatchdogTick(steadyNowNs()); });
  if (config.glr.enabled) {
    p.subscribe<navbus::FilterDiagnosticsPubSubType>(
        topic::kFilterDiagnostics, profile::kDiagnosticsReader,
        [this](const navbus::FilterDiagnostics& m, const auto&) { pipeline_.onDiagnostics(m); });
  }
}

template <class PubSubType, class IdFn, class TimeFn>
void FaultManagerNode::watch(const std::string& topic, const std::string& profile, StreamKind kind,
                             IdFn id, TimeFn time) {
  bus::ReaderCallbacks callbacks;
  callbacks.on_deadline = [this,
                           kind](const eprosima::fastdds::dds::RequestedDeadlineMissedStatus& st) {
    auto it = instances_.find({kind, st.last_instance_handle});
    if (it != instances_.end()) pipeline_.onDeadlineMissed(kind, it->second, steadyNowNs());
  };
  callbacks.on_disposed = [this, kind](const eprosima::fastrtps::rtps::InstanceHandle_t& h) {
    auto it = instances_.find({kind, h});
    if (it == instances_.end()) return;
    pipeline_.onStreamEnded(kind, it->second);
    if (kind == StreamKind::kImu && on_imu_ended_) on_imu_ended_();
  };
  callbacks.on_liveliness = [this,
                             kind](const eprosima::fastdds::dds::LivelinessChangedStatus& st) {
    if (st.alive_count == 0 && st.alive_count_change < 0)
      pipeline_.onWritersGone(kind, steadyNowNs());
  };
  bus::WriterGate& writers =
      writers_.try_emplace(topic, topic, participant_.health().stream(topic)).first->second;
  auto* reader = participant_.subscribe<PubSubType>(
      topic, profile,
      [this, topic, kind, id, time, &writers](const typename PubSubType::type& m,
                                              const eprosima::fastdds::dds::SampleInfo& info) {
        switch (writers.check(id(m), info)) {
          case bus::WriterPins::Verdict::kNewSecondWriter:
            pipeline_.onSecondWriter(kind, id(m), time(m));
            return;
          case bus::WriterPins::Verdict::kSecondWriter:
            return;
          default:
            break;
        }
        instances_[{kind, info.instance_handle}] = id(m);
        if constexpr (std::is_same_v<typename PubSubType::type, navbus::ImuIncrementBlock>) {
          // The block is counted under its topic; each element is received (and watched) as
          // one increment, under the increment topic, as the filter counts them.
          ++participant_.health().stream(topic).accepted;
          bus::StreamCounters& increments = participant_.health().stream(bus::topic::kImuIncrement);
          const std::int64_t now = steadyNowNs();
          for (const navbus::ImuIncrement& increment : m.increments()) {
            ++increments.received;
            pipeline_.onStreamSample(kind, id(m), increment.seq(), increment.time_gps_ns(), now);
          }
          return;
        } else {
          pipeline_.onStreamSample(kind, id(m), m.seq(), time(m), steadyNowNs());
        }
        if constexpr (std::is_same_v<typename PubSubType::type, navbus::ImuRawBlock>) {
          pipeline_.onRawBlock(m);
        }
      },
      callbacks);
  // The decisions quote the reader's own requested deadline (from the QoS profile) as threshold.
  const auto period = reader->get_qos().deadline().period;
  pipeline_.setDeadline(
      kind, static_cast<double>(period.seconds) + 1e-9 * static_cast<double>(period.nanosec));
}

}  // namespace navbus::fault_manager
