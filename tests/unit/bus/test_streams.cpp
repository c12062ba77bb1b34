// The stream table (bus/streams.hpp) is consistent with itself and with the generated types.
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "navbus/bus/streams.hpp"

namespace navbus::bus {
namespace {

TEST(StreamTable, EachSensorTopicNamesItsGeneratedTypeAndKind) {
  std::size_t row = 0;
  forEachSensorMessage([&row](auto tag) {
    using Traits = SensorMessage<typename decltype(tag)::type>;
    typename Traits::PubSubType type_support;
    ASSERT_LT(row, kSensorTopics.size());
    EXPECT_EQ(&Traits::kTopic, &kSensorTopics[row]) << "forEachSensorMessage follows the table";
    EXPECT_EQ(std::string(Traits::kTopic.type_name), type_support.getName());
    EXPECT_EQ(findSensorTopic(Traits::kTopic.topic), &kSensorTopics[row]);
    ++row;
  });
  EXPECT_EQ(row, kSensorTopics.size()) << "every row has a message type";
  EXPECT_EQ(findSensorTopic(topic::kNavSolution), nullptr);
}

TEST(StreamTable, EachKindHasItsCountingTopicAndDistinctSourceRankAndName) {
  std::set<int> sources, ranks;
  std::set<std::string> names;
  for (const StreamKindInfo& kind : kStreamKinds) {
    const SensorTopic* counting = findSensorTopic(kind.topic);
    ASSERT_NE(counting, nullptr) << kind.name;
    EXPECT_EQ(counting->kind, kind.kind) << kind.name;
    EXPECT_TRUE(sources.insert(kind.fault_source).second) << kind.name;
    EXPECT_TRUE(names.insert(kind.name).second) << kind.name;
    if (kind.merge_rank != kNotMerged) {
      EXPECT_TRUE(ranks.insert(kind.merge_rank).second) << kind.name;
    }
  }
  EXPECT_EQ(streamInfo(StreamKind::kImu).merge_rank, *ranks.begin())
      << "the increment comes first at equal data time";
}

}  // namespace
}  // namespace navbus::bus
