// Every navbus topic the bus tool knows: its name, reader profile and formatters.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "navbus/bus/participant.hpp"

namespace navbus::tool {

/// Receives samples as text and CSV rows, computed only when asked for.
struct SampleSink {
  virtual ~SampleSink() = default;
  virtual void onSample(const std::string& topic, const std::function<std::string()>& text,
                        const std::function<std::vector<std::string>()>& csv_rows) = 0;
};

struct TopicEntry {
  std::string name;
  std::string type_name;
  std::string reader_profile;
  std::string csv_header;
  std::function<void(bus::Participant&, SampleSink&)> subscribe;
};

const std::vector<TopicEntry>& topicRegistry();
/// nullptr if the topic is not a navbus topic.
const TopicEntry* findTopic(const std::string& name);

}  // namespace navbus::tool
