// Every navbus topic the bus tool knows: its name, reader profile and formatters.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "navbus/bus/participant.hpp"
#include "navbus/tool/foxglove_channels.hpp"

namespace navbus::tool {

/// When a sample was written (the writer's DDS source time stamp) and received [ns, the
/// writers' and this host's system clocks].
struct SampleTimes {
  std::int64_t source_ns{0};
  std::int64_t reception_ns{0};
};

/// One sample's renderings, each computed only when asked for.
struct SampleViews {
  std::function<std::string()> text;
  std::function<std::vector<std::string>()> csv_rows;
  /// The sample serialized by its type's own serializer: XCDR1 little endian with its 4-byte
  /// encapsulation header, the bytes a navbus writer puts on the wire (DDS hands readers the
  /// deserialized sample, so this is its re-serialization).
  std::function<std::vector<std::uint8_t>()> cdr;
  /// Its message on a channel in Foxglove's schemas (foxglove_channels.hpp), if its type has one.
  std::function<std::optional<DerivedMessage>()> derived;
};

/// Receives samples.
struct SampleSink {
  virtual ~SampleSink() = default;
  virtual void onSample(const std::string& topic, const SampleTimes& times,
                        const SampleViews& sample) = 0;
};

struct TopicEntry {
  std::string name;
  std::string type_name;
  std::string reader_profile;
  std::string csv_header;
  /// Subscribes the sink to the topic with the given reader profile; returns the reader (owned
  /// by the participant).
  std::function<eprosima::fastdds::dds::DataReader*(bus::Participant&, SampleSink&,
                                                    const std::string& reader_profile)>
      subscribe_with;
  /// Subscribes with the topic's own reader profile.
  eprosima::fastdds::dds::DataReader* subscribe(bus::Participant& p, SampleSink& sink) const {
    return subscribe_with(p, sink, reader_profile);
  }
};

const std::vector<TopicEntry>& topicRegistry();
/// nullptr if the topic is not a navbus topic.
const TopicEntry* findTopic(const std::string& name);
/// How a topic is described outside DDS (an MCAP channel, a Foxglove bridge channel): its name
/// ("/" + name under ROS 2 naming), its type's self-contained schema (OMG IDL, or a ROS 2
/// message definition under ROS 2 naming) and the DDS names, for tools that go back to the bus.
struct TopicSchema {
  std::string channel_topic;
  std::string schema_name;
  std::string schema_encoding;  ///< omgidl or ros2msg
  std::string schema;
  std::map<std::string, std::string> metadata;  ///< dds_topic, dds_type, reader_profile
};
/// Throws bus::ConfigError if the type has no schema.
TopicSchema topicSchema(const TopicEntry& entry, bool ros2);

}  // namespace navbus::tool
