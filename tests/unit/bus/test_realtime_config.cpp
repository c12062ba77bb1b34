// The realtime block every participant's configuration takes: its keys, ranges and typos. (What
// the kernel grants is checked by tests/realtime against /proc.)
#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/realtime.hpp"

namespace {

using navbus::bus::ConfigError;
using navbus::bus::readRealtime;
using navbus::bus::SchedulingPolicy;

std::string refusal(const std::string& yaml) {
  try {
    readRealtime(YAML::Load(yaml));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(RealtimeConfig, AbsentRequestsNothingAndAFullBlockIsRead) {
  EXPECT_FALSE(readRealtime(YAML::Load("domain_id: 3")).requested());
  const auto o = readRealtime(
      YAML::Load("realtime: {policy: rr, priority: 20, cpus: [0, 1], lock_memory: true}"));
  EXPECT_EQ(o.policy, SchedulingPolicy::kRoundRobin);
  EXPECT_EQ(o.priority, 20);
  EXPECT_EQ(o.cpus, (std::vector<int>{0, 1}));
  EXPECT_TRUE(o.lock_memory);
  EXPECT_TRUE(o.requested());
}

TEST(RealtimeConfig, EveryMistakeNamesTheKeyAndTheValue) {
  EXPECT_NE(refusal("realtime: {polcy: fifo}").find("realtime.polcy: unknown key"),
            std::string::npos);
  EXPECT_NE(refusal("realtime: {policy: deadline}")
                .find("realtime.policy = 'deadline' is not one of other | fifo | rr"),
            std::string::npos);
  EXPECT_NE(refusal("realtime: {policy: fifo, priority: 0}")
                .find("realtime.priority = 0 is outside 1..99 for policy fifo"),
            std::string::npos);
  EXPECT_NE(
      refusal("realtime: {priority: 5}").find("realtime.priority = 5 needs policy fifo or rr"),
      std::string::npos);
  EXPECT_NE(refusal("realtime: {cpus: [-1]}").find("realtime.cpus: -1 is not a core number"),
            std::string::npos);
  EXPECT_NE(refusal("realtime: {cpus: one}").find("realtime.cpus"), std::string::npos);
  EXPECT_NE(refusal("realtime: {policy: fifo, priority: 200}").find("realtime.priority"),
            std::string::npos);
}
