// The samples of an MCAP recording's channels decoded into their IDL types from the CDR bytes
// (what `navbus record --format mcap` writes): shared by `navbus replay` and `navbus offline
// --recording`.
#pragma once

#include <fastdds/rtps/common/SerializedPayload.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "navbus/bus/config.hpp"
#include "navbus/records/mcap.hpp"

namespace navbus::records {

/// The navbus topic a recorded channel carries: its name, or under ROS 2 naming "/" + name.
inline std::string navbusTopicOfChannel(const std::string& channel_topic) {
  return channel_topic.rfind('/', 0) == 0 ? channel_topic.substr(1) : channel_topic;
}

/// The channel of `topic` in `c`, or nullptr.
inline const McapChannel* channelOfTopic(const McapContents& c, const std::string& topic) {
  for (const auto& [id, channel] : c.channels) {
    if (navbusTopicOfChannel(channel.topic) == topic) return &channel;
  }
  return nullptr;
}

/// One channel's messages in file order, decoded; `publish_ns` (optional) gets each message's
/// publish time (the DDS source time stamp). Throws bus::ConfigError naming the file, the
/// channel and the message that is not CDR of the type.
template <class PubSubType>
std::vector<typename PubSubType::type> decodeChannel(
    const std::string& file, const McapContents& c, const McapChannel& channel,
    std::vector<std::int64_t>* publish_ns = nullptr) {
  if (channel.message_encoding != "cdr") {
    throw bus::ConfigError(file + ": channel '" + channel.topic + "' has message encoding '" +
                           channel.message_encoding + "', not cdr");
  }
  PubSubType type;
  std::vector<typename PubSubType::type> out;
  for (const McapMessage& m : c.messages) {
    if (m.channel_id != channel.id) continue;
    eprosima::fastrtps::rtps::SerializedPayload_t payload(
        static_cast<std::uint32_t>(m.data.size()));
    std::copy(m.data.begin(), m.data.end(), payload.data);
    payload.length = static_cast<std::uint32_t>(m.data.size());
    out.emplace_back();
    if (!type.deserialize(&payload, &out.back())) {
      throw bus::ConfigError(file + ": channel '" + channel.topic + "' message " +
                             std::to_string(out.size()) + " (sequence " +
                             std::to_string(m.sequence) + ") is not a valid " + type.getName());
    }
    if (publish_ns != nullptr) publish_ns->push_back(static_cast<std::int64_t>(m.publish_time_ns));
  }
  return out;
}

}  // namespace navbus::records
