#include "navbus/fault_manager/fault_manager_node.hpp"

#include <algorithm>
#include <chrono>
#include <type_traits>

#include <navbus_idl/HealthPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "navbus/bus/topics.hpp"
#include "navbus/bus/writer_gate.hpp"

namespace navbus::fault_manager {

namespace {
namespace dds = eprosima::fastdds::dds;

std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// The participant of the sample's DDS writer: its GUID prefix.
StreamWatchdog::WriterParticipant writerParticipant(const dds::SampleInfo& info) {
  const bus::WriterId writer = bus::writerId(info);
  StreamWatchdog::WriterParticipant participant{};
  std::copy_n(writer.begin(), participant.size(), participant.begin());
  return participant;
}
}  // namespace

FaultManagerNode::FaultManagerNode(bus::Participant& p, const FaultManagerConfig& config)
    : participant_(p),
      decision_writer_(p.createWriter<navbus::FaultDecisionPubSubType>(
          bus::topic::kFaultDecision, bus::profile::kDecisionWriter)),
      command_writer_(p.createWriter<navbus::FilterCommandPubSubType>(
          bus::topic::kFilterCommand, bus::profile::kDecisionWriter)),
      progress_writer_(p.createWriter<navbus::FaultMonitorProgressPubSubType>(
          bus::topic::kFaultProgress, bus::profile::kProgressWriter)),
      pipeline_(config, p.health(),
                {[this](const navbus::FaultDecision& d) { decision_writer_.write(d); },
                 [this](const navbus::FilterCommand& c) { command_writer_.write(c); },
                 [this](const navbus::FaultMonitorProgress& r) { progress_writer_.write(r); }},
                bus::wallTimeNowNs()),
      sensors_(p, streamEvents()),
      parity_sensors_(p, detectorEvents()),
      receiver_sensors_(p, detectorEvents()) {
  using namespace bus;
  watch<navbus::ImuIncrement>(profile::kSensorWatchdogReader);
  // Fast pacing's blocks of increments: each element is watched as one increment.
  watch<navbus::ImuIncrementBlock>(profile::kSensorWatchdogReader);
  watch<navbus::ImuRawBlock>(profile::kRawImuMonitorReader);
  watch<navbus::GnssObservationEpoch>(profile::kMeasurementWatchdogReader);
  watch<navbus::GnssFix>(profile::kMeasurementWatchdogReader);
  watch<navbus::StarTrackerAttitude>(profile::kMeasurementWatchdogReader);
  // And of epochs, fixes and attitudes.
  watch<navbus::GnssObservationEpochBlock>(profile::kMeasurementWatchdogReader);
  watch<navbus::GnssFixBlock>(profile::kMeasurementWatchdogReader);
  watch<navbus::StarTrackerAttitudeBlock>(profile::kMeasurementWatchdogReader);
  watchAnnouncedEnds();
  // Confirms suspect streams (a DDS deadline event before the own silence reached it) within
  // this period of their silence reaching the deadline.
  p.addTimer(std::chrono::milliseconds(10), [this] { pipeline_.onWatchdogTick(running()); });
  p.subscribe<navbus::FilterCommandOutcomePubSubType>(
      topic::kCommandOutcome, profile::kDecisionReader,
      [this](const navbus::FilterCommandOutcome& o, const auto&) {
        const bool was = pipeline_.degraded();
        pipeline_.onCommandOutcome(o);
        if (pipeline_.degraded() != was)
          participant_.setState(pipeline_.degraded() ? navbus::STATE_DEGRADED
                                                     : navbus::STATE_RUNNING);
      });
  if (config.parity.enabled) {
    subscribeIncrements();
    // The lanes' word on two units the parity test cannot tell apart (every lane solution).
    p.subscribe<navbus::LaneSolutionPubSubType>(
        topic::kLaneSolution, profile::kSolutionReader,
        [this](const navbus::LaneSolution& l, const auto&) { pipeline_.onLaneSolution(l); });
  }
  // The cross-receiver test needs every epoch of every receiver: a reliable reader (the
  // filter's profile for observations).
  if (config.receivers.enabled) {
    receiver_sensors_.subscribe<navbus::GnssObservationEpoch>(
        profile::kMeasurementReader,
        [this](const navbus::GnssObservationEpoch& m) { pipeline_.onGnssEpoch(m); });
    receiver_sensors_.subscribe<navbus::GnssObservationEpochBlock>(
        profile::kMeasurementReader, [this](const navbus::GnssObservationEpochBlock& m) {
          for (const navbus::GnssObservationEpoch& epoch : m.epochs()) pipeline_.onGnssEpoch(epoch);
        });
  }
  if (config.glr.enabled) {
    p.subscribe<navbus::FilterDiagnosticsPubSubType>(
        topic::kFilterDiagnostics, profile::kDiagnosticsReader,
        [this](const navbus::FilterDiagnostics& m, const auto&) { pipeline_.onDiagnostics(m); });
  }
}

bus::SensorReaders::Events FaultManagerNode::detectorEvents() {
  // A detector's reliable reader of a watched topic (the parity test's, the cross-receiver
  // test's): the writer's dispose may reach it and not the watchdog's best-effort reader of the
  // same topic (measured: a replay of the triplex, Fast DDS 2.9, 4 of 4 runs: only the parity
  // reader got the three units' ends, and the watchdog declared them LOST 1 s later). The end
  // is the stream's either way (a second notice of it changes nothing).
  bus::SensorReaders::Events events;
  events.ended = [this](StreamKind kind, std::uint32_t id, std::uint64_t last_time_gps_ns) {
    if (kind == StreamKind::kImu) pipeline_.onParityUnitEnded(id);
    running();
    // This reader's last time is the stream's end: the watchdog's reader, behind, may still
    // take samples up to it, which belong to this run (with the watchdog's own last time as the
    // end they started a new one, which went LOST 2 s later: a replay under the sanitizers).
    pipeline_.onStreamEnded(kind, id, last_time_gps_ns);
    // --exit-when-ended: the end the watchdog's reader may not have taken.
    if (kind == StreamKind::kImu && stop_after_end_ != nullptr) stop_after_end_->ended();
  };
  return events;
}

void FaultManagerNode::subscribeIncrements() {
  // The parity test needs every increment of every unit: reliable readers (the filter's
  // profile), which back-pressure the simulator as the filter's do; watchdog events are the
  // best-effort readers' business.
  using namespace bus;
  parity_sensors_.subscribe<navbus::ImuIncrement>(
      profile::kSensorReader,
      [this](const navbus::ImuIncrement& m) { pipeline_.onImuIncrement(m); });
  parity_sensors_.subscribe<navbus::ImuIncrementBlock>(
      profile::kSensorReader, [this](const navbus::ImuIncrementBlock& m) {
        for (const navbus::ImuIncrement& increment : m.increments())
          pipeline_.onImuIncrement(increment);
      });
}

void FaultManagerNode::watchAnnouncedEnds() {
  // A writer's announced end, also in its health report (reliable): the watchdog's best-effort
  // readers can lose the dispose (the compose demo under DDS Security: the end of three streams
  // lost with blocks of increments, and the simulator's leaving judged a loss). A participant
  // ends only the streams it wrote itself (the GUID prefix of the report's writer).
  participant_.subscribe<navbus::HealthPubSubType>(
      bus::topic::kHealth, bus::profile::kHealthReader,
      [this](const navbus::Health& h, const dds::SampleInfo& info) {
        if (h.state() != navbus::STATE_ENDED) return;
        running();
        for (const StreamKey& key : pipeline_.onWriterParticipantEnded(writerParticipant(info))) {
          if (key.kind == StreamKind::kImu && stop_after_end_ != nullptr) stop_after_end_->ended();
        }
      });
}

std::int64_t FaultManagerNode::running() {
  const std::int64_t now = steadyNowNs();
  if (const auto stalled = stalls_.running(now)) pipeline_.resumedAfterStall(now, *stalled);
  return now;
}

bus::SensorReaders::Events FaultManagerNode::streamEvents() {
  // Each event first asks whether this process was stopped since its last turn: what DDS
  // reports right after a stall (deadlines, liveliness) may be this process's own silence.
  bus::SensorReaders::Events events;
  events.ended = [this](StreamKind kind, std::uint32_t id, std::uint64_t last_time_gps_ns) {
    running();
    pipeline_.onStreamEnded(kind, id, last_time_gps_ns);
    if (kind == StreamKind::kImu && stop_after_end_ != nullptr) stop_after_end_->ended();
  };
  events.deadline_missed = [this](StreamKind kind, std::uint32_t id) {
    pipeline_.onDeadlineMissed(kind, id, running());
  };
  events.writers_gone = [this](StreamKind kind) { pipeline_.onWritersGone(kind, running()); };
  events.second_writer = [this](StreamKind kind, std::uint32_t id, std::uint64_t time_gps_ns) {
    running();
    pipeline_.onSecondWriter(kind, id, time_gps_ns);
  };
  events.writers_alive = [this](StreamKind kind, bool alive) {
    running();
    if (alive) pipeline_.onWritersAlive(kind);
    if (kind == StreamKind::kImu && stop_after_end_ != nullptr)
      stop_after_end_->writersAlive(alive);
  };
  return events;
}

template <class Block, class Elements>
void FaultManagerNode::watchElements(const Block& m, const char* element_topic,
                                     const Elements& elements,
                                     const StreamWatchdog::WriterParticipant& writer) {
  // The block is counted under its topic; each element is received (and watched) as one
  // sample of its own topic, as the filter counts them.
  using Traits = bus::SensorMessage<Block>;
  participant_.health().stream(Traits::kTopic.topic).countAccepted(Traits::sensorId(m));
  bus::StreamCounters& counters = participant_.health().stream(element_topic);
  const std::int64_t now = steadyNowNs();
  for (const auto& element : elements) {
    ++counters.received;
    pipeline_.onStreamSample(Traits::kTopic.kind, Traits::sensorId(m), element.seq(),
                             element.time_gps_ns(), now,
                             {StreamWatchdog::Delivery::kBlock, writer});
  }
}

template <class Message>
void FaultManagerNode::watch(const char* profile) {
  using Traits = bus::SensorMessage<Message>;
  static constexpr StreamKind kind = Traits::kTopic.kind;  // no capture needed
  auto* reader =
      sensors_.subscribe<Message>(profile, [this](const Message& m, const dds::SampleInfo& info) {
        const StreamWatchdog::WriterParticipant writer = writerParticipant(info);
        if constexpr (std::is_same_v<Message, navbus::ImuIncrementBlock>) {
          watchElements(m, bus::topic::kImuIncrement, m.increments(), writer);
        } else if constexpr (bus::kIsSensorBlock<Message>) {
          using Element = typename bus::SensorBlock<Message>::Element;
          watchElements(m, bus::SensorMessage<Element>::kTopic.topic,
                        bus::SensorBlock<Message>::elements(m), writer);
        } else {
          pipeline_.onStreamSample(kind, Traits::sensorId(m), m.seq(), Traits::timeGpsNs(m),
                                   steadyNowNs(), {StreamWatchdog::Delivery::kSample, writer});
          if constexpr (std::is_same_v<Message, navbus::ImuRawBlock>) pipeline_.onRawBlock(m);
        }
      });
  // The decisions quote the reader's own requested deadline (from the QoS profile) as threshold.
  const auto period = reader->get_qos().deadline().period;
  pipeline_.setDeadline(
      kind, static_cast<double>(period.seconds) + 1e-9 * static_cast<double>(period.nanosec));
}

}  // namespace navbus::fault_manager
