#include "navbus/tool/topic_registry.hpp"

#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/HealthPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "navbus/bus/topics.hpp"
#include "navbus/records/formatters.hpp"

namespace navbus::tool {

namespace {
template <class PubSubType>
TopicEntry entry(const char* topic, const char* profile) {
  using T = typename PubSubType::type;
  PubSubType type;
  return TopicEntry{
      topic, type.getName(), profile, records::csvHeader<T>(),
      [topic, profile](bus::Participant& p, SampleSink& sink) {
        p.subscribe<PubSubType>(topic, profile, [topic, &sink](const T& m, const auto& info) {
          const SampleTimes times{info.source_timestamp.to_ns(), info.reception_timestamp.to_ns()};
          sink.onSample(
              topic, times, [&m] { return records::textOf(m); },
              [&m] { return records::csvRows(m); });
        });
      }};
}
}  // namespace

const std::vector<TopicEntry>& topicRegistry() {
  using namespace bus;
  static const std::vector<TopicEntry> registry = {
      entry<navbus::ImuIncrementPubSubType>(topic::kImuIncrement, profile::kSensorReader),
      entry<navbus::ImuIncrementBlockPubSubType>(topic::kImuIncrementBlock, profile::kSensorReader),
      entry<navbus::ImuRawBlockPubSubType>(topic::kImuRaw, profile::kSensorReader),
      entry<navbus::GnssObservationEpochPubSubType>(topic::kGnssObservations,
                                                    profile::kMeasurementReader),
      entry<navbus::GnssFixPubSubType>(topic::kGnssFix, profile::kMeasurementReader),
      entry<navbus::StarTrackerAttitudePubSubType>(topic::kStarTracker,
                                                   profile::kMeasurementReader),
      entry<navbus::NavigationSolutionPubSubType>(topic::kNavSolution, profile::kSolutionReader),
      entry<navbus::NavigationSolutionPubSubType>(topic::kNavSolutionLowLatency,
                                                  profile::kLowLatencySolutionReader),
      entry<navbus::FilterDiagnosticsPubSubType>(topic::kFilterDiagnostics,
                                                 profile::kDiagnosticsReader),
      entry<navbus::FaultDecisionPubSubType>(topic::kFaultDecision, profile::kDecisionReader),
      entry<navbus::FilterCommandPubSubType>(topic::kFilterCommand, profile::kDecisionReader),
      entry<navbus::HealthPubSubType>(topic::kHealth, profile::kHealthReader),
  };
  return registry;
}

std::string recordFileName(const std::string& topic) {
  std::string file = topic;
  for (char& c : file) {
    if (c == '/') c = '_';
  }
  return file + ".csv";
}

const TopicEntry* findTopic(const std::string& name) {
  for (const auto& e : topicRegistry()) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

}  // namespace navbus::tool
