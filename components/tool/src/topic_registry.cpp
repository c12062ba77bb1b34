#include "navbus/tool/topic_registry.hpp"

#include <algorithm>

#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/HealthPubSubTypes.h>
#include <navbus_idl/IdlSchemas.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/dds_context.hpp"
#include "navbus/bus/streams.hpp"
#include "navbus/records/formatters.hpp"

namespace navbus::tool {

namespace {

template <class PubSubType>
std::vector<std::uint8_t> serialized(const typename PubSubType::type& m) {
  PubSubType type;
  auto* data = const_cast<typename PubSubType::type*>(&m);  // the serializer only reads it
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(data)());
  if (!type.serialize(data, &payload)) {
    throw std::runtime_error(std::string("cannot serialize a sample of ") + type.getName());
  }
  return {payload.data, payload.data + payload.length};
}

template <class PubSubType>
TopicEntry entry(const char* topic, const char* profile) {
  using T = typename PubSubType::type;
  PubSubType type;
  return TopicEntry{
      topic, type.getName(), profile, records::csvHeader<T>(),
      [topic](bus::Participant& p, SampleSink& sink, const std::string& reader_profile) {
        return p.subscribe<
            PubSubType>(topic, reader_profile, [topic, &sink](const T& m, const auto& info) {
          const SampleTimes times{info.source_timestamp.to_ns(), info.reception_timestamp.to_ns()};
          sink.onSample(
              topic, times,
              SampleViews{[&m] { return records::textOf(m); }, [&m] { return records::csvRows(m); },
                          [&m] { return serialized<PubSubType>(m); },
                          [&m, &times] {
                            return derivedMessage(
                                m, static_cast<std::uint64_t>(
                                       std::max<std::int64_t>(times.reception_ns, 0)));
                          }});
        });
      }};
}

std::vector<TopicEntry> makeRegistry() {
  using namespace bus;
  std::vector<TopicEntry> registry;
  forEachSensorMessage([&registry](auto tag) {
    using Traits = SensorMessage<typename decltype(tag)::type>;
    registry.push_back(
        entry<typename Traits::PubSubType>(Traits::kTopic.topic, Traits::kTopic.reader_profile));
  });
  registry.push_back(
      entry<navbus::NavigationSolutionPubSubType>(topic::kNavSolution, profile::kSolutionReader));
  registry.push_back(entry<navbus::NavigationSolutionPubSubType>(
      topic::kNavSolutionLowLatency, profile::kLowLatencySolutionReader));
  registry.push_back(
      entry<navbus::LaneSolutionPubSubType>(topic::kLaneSolution, profile::kSolutionReader));
  registry.push_back(entry<navbus::FilterDiagnosticsPubSubType>(topic::kFilterDiagnostics,
                                                                profile::kDiagnosticsReader));
  registry.push_back(
      entry<navbus::FaultDecisionPubSubType>(topic::kFaultDecision, profile::kDecisionReader));
  registry.push_back(
      entry<navbus::FilterCommandPubSubType>(topic::kFilterCommand, profile::kDecisionReader));
  registry.push_back(entry<navbus::FilterCommandOutcomePubSubType>(topic::kCommandOutcome,
                                                                   profile::kDecisionReader));
  registry.push_back(entry<navbus::FaultMonitorProgressPubSubType>(topic::kFaultProgress,
                                                                   profile::kProgressReader));
  registry.push_back(entry<navbus::HealthPubSubType>(topic::kHealth, profile::kHealthReader));
  return registry;
}
}  // namespace

const std::vector<TopicEntry>& topicRegistry() {
  static const std::vector<TopicEntry> registry = makeRegistry();
  return registry;
}

TopicSchema topicSchema(const TopicEntry& e, bool ros2) {
  const idl_schemas::TypeSchema* schema = idl_schemas::find(e.type_name);
  if (schema == nullptr) {
    throw bus::ConfigError("no schema for type '" + e.type_name + "' of " + e.name);
  }
  TopicSchema t;
  t.channel_topic = ros2 ? "/" + e.name : e.name;
  t.schema_name = ros2 ? std::string(schema->ros2_name) : std::string(schema->type_name);
  t.schema_encoding = ros2 ? "ros2msg" : "omgidl";
  t.schema = ros2 ? std::string(schema->ros2msg) : std::string(schema->omgidl);
  t.metadata = {{"dds_topic", ros2 ? bus::ros2TopicName(e.name) : e.name},
                {"dds_type", ros2 ? bus::ros2TypeName(e.type_name) : e.type_name},
                {"reader_profile", e.reader_profile}};
  return t;
}

const TopicEntry* findTopic(const std::string& name) {
  for (const auto& e : topicRegistry()) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

}  // namespace navbus::tool
