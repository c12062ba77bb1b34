// The sensor readers of a participant that follows streams (the filter, the fault manager):
// one subscription per sensor topic (bus/streams.hpp), samples of the sensor's owning writer
// only (one writer per sensor id, bus::WriterGate), and the DDS events that name an instance
// (a disposal: the writer announced the end of its data; a missed deadline) turned into
// (stream kind, sensor id).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <type_traits>
#include <utility>

#include "navbus/bus/participant.hpp"
#include "navbus/bus/streams.hpp"
#include "navbus/bus/writer_gate.hpp"

namespace navbus::bus {

class SensorReaders {
 public:
  /// What the owner is told besides the samples; every one may be empty.
  struct Events {
    /// The stream's writer disposed the sensor's instance: the stream ended as announced.
    /// `last_time_gps_ns`: the data time of the last sample of the stream this reader took (in
    /// order of the writer, before the dispose): where the stream ended, whatever another reader
    /// of the participant, behind, has seen of it so far.
    std::function<void(StreamKind, std::uint32_t sensor_id, std::uint64_t last_time_gps_ns)>
        ended{};
    /// The reader's requested deadline passed without a sample of the sensor.
    std::function<void(StreamKind, std::uint32_t sensor_id)> deadline_missed{};
    /// Every writer of the topic lost its liveliness.
    std::function<void(StreamKind)> writers_gone{};
    /// A second writer claims a sensor whose owner is alive, seen for the first time (its
    /// samples are kept out and counted either way).
    std::function<void(StreamKind, std::uint32_t sensor_id, std::uint64_t time_gps_ns)>
        second_writer{};
    /// Whether any writer of the topic is alive, at each change of its liveliness.
    std::function<void(StreamKind, bool alive)> writers_alive{};
  };

  SensorReaders(Participant& participant, Events events)
      : participant_(participant), events_(std::move(events)) {}

  /// Subscribes the topic of `Message` (SensorMessage<Message>) with `profile`; `handler(m)`,
  /// or `handler(m, info)`, gets each sample of the sensor's owner. Returns the reader (its QoS
  /// tells the deadline).
  template <class Message, class Handler>
  eprosima::fastdds::dds::DataReader* subscribe(const char* profile, Handler handler) {
    using Traits = SensorMessage<Message>;
    const SensorTopic& row = Traits::kTopic;
    WriterGate& writers =
        gates_.try_emplace(row.topic, row.topic, participant_.health().stream(row.topic))
            .first->second;
    return participant_.subscribe<typename Traits::PubSubType>(
        row.topic, profile,
        [this, kind = row.kind, &writers, handler](const Message& m,
                                                   const eprosima::fastdds::dds::SampleInfo& info) {
          if (!admit(kind, writers, Traits::sensorId(m), Traits::timeGpsNs(m), info)) return;
          if constexpr (std::is_invocable_v<Handler, const Message&,
                                            const eprosima::fastdds::dds::SampleInfo&>) {
            handler(m, info);
          } else {
            handler(m);
          }
        },
        callbacks(row.kind));
  }

 private:
  /// What an instance is: disposals and deadline statuses name only the instance.
  struct Instance {
    std::uint32_t sensor_id{0};
    std::uint64_t last_time_gps_ns{0};  ///< of the last sample taken
  };
  /// True if the sample is its sensor's owner's (and remembers the sensor's instance handle).
  bool admit(StreamKind kind, WriterGate& writers, std::uint32_t sensor_id,
             std::uint64_t time_gps_ns, const eprosima::fastdds::dds::SampleInfo& info);
  ReaderCallbacks callbacks(StreamKind kind);
  /// An instance seen on a stream of `kind`; nullptr if none was.
  const Instance* instanceOf(StreamKind kind,
                             const eprosima::fastrtps::rtps::InstanceHandle_t& handle) const;

  Participant& participant_;
  Events events_;
  /// One writer per sensor id on each topic (a second writer's samples are kept out).
  std::map<std::string, WriterGate> gates_;
  /// DDS instance handle -> its sensor and last data time, per stream kind (disposals and
  /// deadline statuses name only the instance).
  std::map<std::pair<StreamKind, eprosima::fastrtps::rtps::InstanceHandle_t>, Instance> instances_;
};

}  // namespace navbus::bus
