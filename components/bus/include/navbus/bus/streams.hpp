// The sensor streams, in one table: for each stream its kind, name, fault source and place in the
// filter's ordered merge, and for each topic that carries one its message type and QoS
// profiles. The filter and fault-manager participants, the stream watchdog, the tool's topic
// registry, replay and the simulator's writers read these rows; nothing else spells them. A new
// sensor type adds a row here (docs/extending/add_sensor_type.md).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <type_traits>
#include <vector>

#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "navbus/bus/stream_kind.hpp"
#include "navbus/bus/topics.hpp"

namespace navbus::bus {

/// The filter does not merge the stream (StreamKindInfo::merge_rank).
inline constexpr int kNotMerged = -1;

struct StreamKindInfo {
  StreamKind kind;
  const char* name;                  ///< in logs, fault decisions' descriptions and the CLI
  const char* topic;                 ///< the topic whose health counts each sample of the stream
  navbus::FaultSource fault_source;  ///< names the stream in a watchdog's FaultDecision
  /// Order in the filter's merge at equal data time (lower first: the increment is integrated
  /// before the measurements of its time are used); kNotMerged if the filter does not read it.
  int merge_rank;
};

inline constexpr std::array<StreamKindInfo, 5> kStreamKinds{{
    {StreamKind::kImu, "imu", topic::kImuIncrement, navbus::SOURCE_IMU_STREAM, 0},
    {StreamKind::kImuRaw, "imu-raw", topic::kImuRaw, navbus::SOURCE_IMU_RAW_STREAM, kNotMerged},
    {StreamKind::kGnssObservations, "gnss-observations", topic::kGnssObservations,
     navbus::SOURCE_GNSS_OBS_STREAM, 1},
    {StreamKind::kGnssFix, "gnss-fix", topic::kGnssFix, navbus::SOURCE_GNSS_FIX_STREAM, 2},
    {StreamKind::kStarTracker, "star-tracker", topic::kStarTracker, navbus::SOURCE_ST_STREAM, 3},
}};

constexpr const StreamKindInfo& streamInfo(StreamKind kind) {
  return kStreamKinds[static_cast<std::size_t>(kind)];
}

/// A topic that carries a sensor stream (fast pacing carries every merged stream in blocks too).
struct SensorTopic {
  const char* topic;
  StreamKind kind;
  const char* type_name;         ///< the IDL type (a test checks it against the type support)
  const char* reader_profile;    ///< the filter's and the recorder's reader
  const char* watchdog_profile;  ///< the fault manager's reader (its deadline times the watchdog)
  const char* writer_profile;    ///< the simulator in real time, and replay
  const char* fast_writer_profile;  ///< the simulator in fast pacing
};

inline constexpr std::array<SensorTopic, 9> kSensorTopics{{
    {topic::kImuIncrement, StreamKind::kImu, "navbus::ImuIncrement", profile::kSensorReader,
     profile::kSensorWatchdogReader, profile::kSensorWriter, profile::kSensorWriterFastPacing},
    {topic::kImuIncrementBlock, StreamKind::kImu, "navbus::ImuIncrementBlock",
     profile::kSensorReader, profile::kSensorWatchdogReader, profile::kSensorWriter,
     profile::kSensorWriterFastPacing},
    {topic::kImuRaw, StreamKind::kImuRaw, "navbus::ImuRawBlock", profile::kSensorReader,
     profile::kRawImuMonitorReader, profile::kSensorWriter, profile::kSensorWriterFastPacing},
    {topic::kGnssObservations, StreamKind::kGnssObservations, "navbus::GnssObservationEpoch",
     profile::kMeasurementReader, profile::kMeasurementWatchdogReader, profile::kMeasurementWriter,
     profile::kMeasurementWriterFastPacing},
    {topic::kGnssFix, StreamKind::kGnssFix, "navbus::GnssFix", profile::kMeasurementReader,
     profile::kMeasurementWatchdogReader, profile::kMeasurementWriter,
     profile::kMeasurementWriterFastPacing},
    {topic::kStarTracker, StreamKind::kStarTracker, "navbus::StarTrackerAttitude",
     profile::kMeasurementReader, profile::kMeasurementWatchdogReader, profile::kMeasurementWriter,
     profile::kMeasurementWriterFastPacing},
    {topic::kGnssObservationsBlock, StreamKind::kGnssObservations,
     "navbus::GnssObservationEpochBlock", profile::kMeasurementReader,
     profile::kMeasurementWatchdogReader, profile::kMeasurementWriter,
     profile::kMeasurementWriterFastPacing},
    {topic::kGnssFixBlock, StreamKind::kGnssFix, "navbus::GnssFixBlock",
     profile::kMeasurementReader, profile::kMeasurementWatchdogReader, profile::kMeasurementWriter,
     profile::kMeasurementWriterFastPacing},
    {topic::kStarTrackerBlock, StreamKind::kStarTracker, "navbus::StarTrackerAttitudeBlock",
     profile::kMeasurementReader, profile::kMeasurementWatchdogReader, profile::kMeasurementWriter,
     profile::kMeasurementWriterFastPacing},
}};

/// The row of a sensor topic; nullptr if `topic` carries no sensor stream.
const SensorTopic* findSensorTopic(std::string_view topic);

/// Each sensor message type: its row in kSensorTopics, its type support, and where its sensor
/// id and data time are.
template <class Message>
struct SensorMessage;

template <>
struct SensorMessage<navbus::ImuIncrement> {
  using PubSubType = navbus::ImuIncrementPubSubType;
  static constexpr const SensorTopic& kTopic = kSensorTopics[0];
  static std::uint32_t sensorId(const navbus::ImuIncrement& m) { return m.sensor_id(); }
  static std::uint64_t timeGpsNs(const navbus::ImuIncrement& m) { return m.time_gps_ns(); }
};

template <>
struct SensorMessage<navbus::ImuIncrementBlock> {
  using PubSubType = navbus::ImuIncrementBlockPubSubType;
  static constexpr const SensorTopic& kTopic = kSensorTopics[1];
  static std::uint32_t sensorId(const navbus::ImuIncrementBlock& m) { return m.sensor_id(); }
  /// Its newest increment's (0 for an empty block).
  static std::uint64_t timeGpsNs(const navbus::ImuIncrementBlock& m) {
    return m.increments().empty() ? std::uint64_t{0} : m.increments().back().time_gps_ns();
  }
};

template <>
struct SensorMessage<navbus::ImuRawBlock> {
  using PubSubType = navbus::ImuRawBlockPubSubType;
  static constexpr const SensorTopic& kTopic = kSensorTopics[2];
  static std::uint32_t sensorId(const navbus::ImuRawBlock& m) { return m.sensor_id(); }
  /// Its first sample's.
  static std::uint64_t timeGpsNs(const navbus::ImuRawBlock& m) {
    return m.first_sample_time_gps_ns();
  }
};

template <>
struct SensorMessage<navbus::GnssObservationEpoch> {
  using PubSubType = navbus::GnssObservationEpochPubSubType;
  static constexpr const SensorTopic& kTopic = kSensorTopics[3];
  static std::uint32_t sensorId(const navbus::GnssObservationEpoch& m) { return m.receiver_id(); }
  static std::uint64_t timeGpsNs(const navbus::GnssObservationEpoch& m) { return m.time_gps_ns(); }
};

template <>
struct SensorMessage<navbus::GnssFix> {
  using PubSubType = navbus::GnssFixPubSubType;
  static constexpr const SensorTopic& kTopic = kSensorTopics[4];
  static std::uint32_t sensorId(const navbus::GnssFix& m) { return m.receiver_id(); }
  static std::uint64_t timeGpsNs(const navbus::GnssFix& m) { return m.time_gps_ns(); }
};

template <>
struct SensorMessage<navbus::StarTrackerAttitude> {
  using PubSubType = navbus::StarTrackerAttitudePubSubType;
  static constexpr const SensorTopic& kTopic = kSensorTopics[5];
  static std::uint32_t sensorId(const navbus::StarTrackerAttitude& m) { return m.tracker_id(); }
  static std::uint64_t timeGpsNs(const navbus::StarTrackerAttitude& m) { return m.time_gps_ns(); }
};

/// The bound of ImuIncrementBlock.increments (idl/Imu.idl).
inline constexpr std::size_t kMaxIncrementsPerBlock = 128;

/// Fast pacing's blocks of the measurement streams: consecutive elements of one sensor's stream
/// in one sample, each element read as one sample of the element's topic.
template <class Block>
struct SensorBlock;

template <>
struct SensorBlock<navbus::GnssObservationEpochBlock> {
  using Element = navbus::GnssObservationEpoch;
  static constexpr const char* kElements = "epochs";      ///< the sequence's field name
  static constexpr const char* kIdField = "receiver_id";  ///< the elements' sensor id field
  static constexpr std::size_t kMaxElements = 8;          ///< the sequence's IDL bound
  static const std::vector<Element>& elements(const navbus::GnssObservationEpochBlock& b) {
    return b.epochs();
  }
  static std::vector<Element>& elements(navbus::GnssObservationEpochBlock& b) { return b.epochs(); }
  static void setSensorId(navbus::GnssObservationEpochBlock& b, std::uint32_t id) {
    b.receiver_id(id);
  }
  static void setElementSensorId(Element& e, std::uint32_t id) { e.receiver_id(id); }
};

template <>
struct SensorBlock<navbus::GnssFixBlock> {
  using Element = navbus::GnssFix;
  static constexpr const char* kElements = "fixes";
  static constexpr const char* kIdField = "receiver_id";
  static constexpr std::size_t kMaxElements = 16;
  static const std::vector<Element>& elements(const navbus::GnssFixBlock& b) { return b.fixes(); }
  static std::vector<Element>& elements(navbus::GnssFixBlock& b) { return b.fixes(); }
  static void setSensorId(navbus::GnssFixBlock& b, std::uint32_t id) { b.receiver_id(id); }
  static void setElementSensorId(Element& e, std::uint32_t id) { e.receiver_id(id); }
};

template <>
struct SensorBlock<navbus::StarTrackerAttitudeBlock> {
  using Element = navbus::StarTrackerAttitude;
  static constexpr const char* kElements = "attitudes";
  static constexpr const char* kIdField = "tracker_id";
  static constexpr std::size_t kMaxElements = 16;
  static const std::vector<Element>& elements(const navbus::StarTrackerAttitudeBlock& b) {
    return b.attitudes();
  }
  static std::vector<Element>& elements(navbus::StarTrackerAttitudeBlock& b) {
    return b.attitudes();
  }
  static void setSensorId(navbus::StarTrackerAttitudeBlock& b, std::uint32_t id) {
    b.tracker_id(id);
  }
  static void setElementSensorId(Element& e, std::uint32_t id) { e.tracker_id(id); }
};

/// Whether T is a measurement block (has a SensorBlock).
template <class T, class = void>
struct IsSensorBlock : std::false_type {};
template <class T>
struct IsSensorBlock<T, std::void_t<typename SensorBlock<T>::Element>> : std::true_type {};
template <class T>
inline constexpr bool kIsSensorBlock = IsSensorBlock<T>::value;

/// The newest element's data time of a measurement block (0 for an empty block).
template <class Block>
std::uint64_t newestElementTimeGpsNs(const Block& m) {
  const auto& e = SensorBlock<Block>::elements(m);
  return e.empty() ? std::uint64_t{0} : e.back().time_gps_ns();
}

template <>
struct SensorMessage<navbus::GnssObservationEpochBlock> {
  using PubSubType = navbus::GnssObservationEpochBlockPubSubType;
  static constexpr const SensorTopic& kTopic = kSensorTopics[6];
  static std::uint32_t sensorId(const navbus::GnssObservationEpochBlock& m) {
    return m.receiver_id();
  }
  static std::uint64_t timeGpsNs(const navbus::GnssObservationEpochBlock& m) {
    return newestElementTimeGpsNs(m);
  }
};

template <>
struct SensorMessage<navbus::GnssFixBlock> {
  using PubSubType = navbus::GnssFixBlockPubSubType;
  static constexpr const SensorTopic& kTopic = kSensorTopics[7];
  static std::uint32_t sensorId(const navbus::GnssFixBlock& m) { return m.receiver_id(); }
  static std::uint64_t timeGpsNs(const navbus::GnssFixBlock& m) {
    return newestElementTimeGpsNs(m);
  }
};

template <>
struct SensorMessage<navbus::StarTrackerAttitudeBlock> {
  using PubSubType = navbus::StarTrackerAttitudeBlockPubSubType;
  static constexpr const SensorTopic& kTopic = kSensorTopics[8];
  static std::uint32_t sensorId(const navbus::StarTrackerAttitudeBlock& m) {
    return m.tracker_id();
  }
  static std::uint64_t timeGpsNs(const navbus::StarTrackerAttitudeBlock& m) {
    return newestElementTimeGpsNs(m);
  }
};

/// Calls `fn(MessageTag<Message>{})` for each sensor message type, in kSensorTopics order (for
/// code that instantiates something per type: readers, writers, CSV loaders).
template <class Message>
struct MessageTag {
  using type = Message;
};
template <class Fn>
void forEachSensorMessage(Fn&& fn) {
  fn(MessageTag<navbus::ImuIncrement>{});
  fn(MessageTag<navbus::ImuIncrementBlock>{});
  fn(MessageTag<navbus::ImuRawBlock>{});
  fn(MessageTag<navbus::GnssObservationEpoch>{});
  fn(MessageTag<navbus::GnssFix>{});
  fn(MessageTag<navbus::StarTrackerAttitude>{});
  fn(MessageTag<navbus::GnssObservationEpochBlock>{});
  fn(MessageTag<navbus::GnssFixBlock>{});
  fn(MessageTag<navbus::StarTrackerAttitudeBlock>{});
}

}  // namespace navbus::bus
