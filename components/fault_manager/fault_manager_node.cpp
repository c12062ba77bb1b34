#include "fault_manager_node.hpp"

#include <chrono>
#include <sstream>

#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "navbus/bus/topics.hpp"

namespace navbus::fault_manager {

namespace {
std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

navbus::FaultSource toSource(StreamKind k) {
  switch (k) {
    case StreamKind::kImu:
      return navbus::SOURCE_IMU_STREAM;
    case StreamKind::kImuRaw:
      return navbus::SOURCE_IMU_RAW_STREAM;
    case StreamKind::kGnssObservations:
      return navbus::SOURCE_GNSS_OBS_STREAM;
    case StreamKind::kGnssFix:
      return navbus::SOURCE_GNSS_FIX_STREAM;
    case StreamKind::kStarTracker:
      return navbus::SOURCE_ST_STREAM;
  }
  return navbus::SOURCE_IMU_STREAM;
}

const char* kindName(StreamKind k) {
  switch (k) {
    case StreamKind::kImu:
      return "imu";
    case StreamKind::kImuRaw:
      return "imu-raw";
    case StreamKind::kGnssObservations:
      return "gnss-observations";
    case StreamKind::kGnssFix:
      return "gnss-fix";
    case StreamKind::kStarTracker:
      return "star-tracker";
  }
  return "?";
}
}  // namespace

FaultManagerNode::FaultManagerNode(bus::Participant& p) : participant_(p) {
  using namespace bus;
  decision_writer_ = p.createWriter<navbus::FaultDecisionPubSubType>(topic::kFaultDecision,
                                                                     profile::kDecisionWriter);
  watch<navbus::ImuIncrementPubSubType>(
      topic::kImuIncrement, profile::kSensorWatchdogReader, StreamKind::kImu,
      [](const auto& m) { return m.sensor_id(); }, [](const auto& m) { return m.time_gps_ns(); });
  watch<navbus::ImuRawBlockPubSubType>(
      topic::kImuRaw, profile::kSensorWatchdogReader, StreamKind::kImuRaw,
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
}

template <class PubSubType, class IdFn, class TimeFn>
void FaultManagerNode::watch(const std::string& topic, const std::string& profile, StreamKind kind,
                             IdFn id, TimeFn time) {
  bus::ReaderCallbacks callbacks;
  callbacks.on_deadline = [this,
                           kind](const eprosima::fastdds::dds::RequestedDeadlineMissedStatus& st) {
    auto it = instances_.find({kind, st.last_instance_handle});
    if (it == instances_.end()) return;
    if (auto e = watchdog_.onDeadlineMissed({kind, it->second}, steadyNowNs())) publish(*e);
  };
  callbacks.on_liveliness = [this,
                             kind](const eprosima::fastdds::dds::LivelinessChangedStatus& st) {
    if (st.alive_count == 0 && st.alive_count_change < 0) {
      for (const auto& e : watchdog_.onWritersGone(kind, steadyNowNs())) publish(e);
    }
  };
  auto* reader = participant_.subscribe<PubSubType>(
      topic, profile,
      [this, topic, kind, id, time](const typename PubSubType::type& m,
                                    const eprosima::fastdds::dds::SampleInfo& info) {
        instances_[{kind, info.instance_handle}] = id(m);
        auto& counters = participant_.health().stream(topic);
        ++counters.accepted;  // observed, not validated: a monitor
        // Best-effort readers may lose samples: count them from the sequence numbers. A
        // restarted writer (time going back) starts a new count.
        auto& tracker = trackers_[kind];
        auto o = tracker.check(id(m), m.seq(), time(m));
        if (o.rejection) {
          tracker.reset(id(m));
          o = tracker.check(id(m), m.seq(), time(m));
        }
        counters.sequence_gaps += o.missing;
        if (auto e = watchdog_.onSample({kind, id(m)}, time(m), steadyNowNs())) publish(*e);
      },
      callbacks);
  // The decisions quote the reader's own requested deadline (from the QoS profile) as threshold.
  const auto period = reader->get_qos().deadline().period;
  deadline_s_[kind] =
      static_cast<double>(period.seconds) + 1e-9 * static_cast<double>(period.nanosec);
}

void FaultManagerNode::publish(const WatchdogEvent& e) {
  navbus::FaultDecision d;
  d.decision_id(next_decision_id_++);
  d.time_gps_ns(e.last_time_gps_ns);
  d.source(toSource(e.key.kind));
  d.sensor_id(e.key.sensor_id);
  d.test_statistic(e.silence_s);
  d.threshold(deadline_s_[e.key.kind]);
  d.magnitude(0.0);
  d.onset_time_gps_ns(e.last_time_gps_ns);
  d.action(e.lost ? navbus::ACTION_STREAM_LOST : navbus::ACTION_STREAM_RESTORED);
  d.detector("watchdog");
  decision_writer_.write(d);
  (e.lost ? lost_decisions_ : restored_decisions_)++;
  spdlog::warn("decision {}: {} stream {} {} (silent {:.3f} s)", d.decision_id(),
               kindName(e.key.kind), e.key.sensor_id, e.lost ? "LOST" : "RESTORED", e.silence_s);
}

std::string FaultManagerNode::summary() const {
  std::ostringstream out;
  out << "decisions published: " << lost_decisions_ << " stream lost, " << restored_decisions_
      << " restored";
  return out.str();
}

}  // namespace navbus::fault_manager
