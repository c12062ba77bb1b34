// The fault manager learns whether its commands closed the loop: its own outcomes only, and
// DEGRADED while the latest one was refused or clamped.
#include <gtest/gtest.h>

#include "navbus/fault_manager/command_outcomes.hpp"

using navbus::fault_manager::CommandOutcomes;

namespace {
navbus::FilterCommandOutcome outcome(std::uint64_t id, navbus::CommandOutcomeKind kind,
                                     const std::string& issuer = "fault-manager",
                                     std::uint64_t run = 5) {
  navbus::FilterCommandOutcome o;
  o.command_id(id);
  o.issuer(issuer);
  o.run_id(run);
  o.outcome(kind);
  return o;
}
}  // namespace

TEST(CommandOutcomes, ARefusedOrClampedCommandDegradesUntilALaterOneIsApplied) {
  CommandOutcomes outcomes("fault-manager", 5);
  EXPECT_TRUE(outcomes.onOutcome(outcome(1, navbus::OUTCOME_APPLIED)));
  EXPECT_FALSE(outcomes.degraded());
  EXPECT_TRUE(outcomes.onOutcome(outcome(2, navbus::OUTCOME_CLAMPED)));
  EXPECT_TRUE(outcomes.degraded());
  EXPECT_TRUE(outcomes.onOutcome(outcome(3, navbus::OUTCOME_REFUSED)));
  EXPECT_TRUE(outcomes.onOutcome(outcome(1, navbus::OUTCOME_APPLIED)));  // an older one, late
  EXPECT_TRUE(outcomes.degraded());
  EXPECT_TRUE(outcomes.onOutcome(outcome(4, navbus::OUTCOME_APPLIED)));
  EXPECT_FALSE(outcomes.degraded());
  EXPECT_EQ(outcomes.applied(), 3u);
  EXPECT_EQ(outcomes.clamped(), 1u);
  EXPECT_EQ(outcomes.refused(), 1u);
}

TEST(CommandOutcomes, OtherIssuersAndEarlierRunsAreNotThisFaultManagers) {
  CommandOutcomes outcomes("fault-manager", 5);
  EXPECT_FALSE(outcomes.onOutcome(outcome(9, navbus::OUTCOME_REFUSED, "operator")));
  EXPECT_FALSE(outcomes.onOutcome(outcome(9, navbus::OUTCOME_REFUSED, "fault-manager", 4)));
  EXPECT_FALSE(outcomes.degraded());
  EXPECT_EQ(outcomes.refused(), 0u);
}

TEST(CommandOutcomes, AStreamTheFilterDoesNotFuseIsNoDegradation) {
  // A redundant receiver's epochs declared lost: the filter refuses the exclusion as not its
  // stream (it fuses the other receiver). Nothing of the filter's is uncured: counted, not
  // DEGRADED; any other refusal still is.
  CommandOutcomes outcomes("fault-manager", 5);
  navbus::FilterCommandOutcome o = outcome(1, navbus::OUTCOME_REFUSED);
  o.kind(navbus::CMD_EXCLUDE_STREAM);
  o.reason(navbus::REJECT_UNEXPECTED_SOURCE);
  EXPECT_TRUE(outcomes.onOutcome(o));
  EXPECT_FALSE(outcomes.degraded());
  EXPECT_EQ(outcomes.refused(), 1u);
  EXPECT_EQ(outcomes.notItsStreams(), 1u);
  o.command_id(2);
  o.kind(navbus::CMD_FAIL_SENSOR_AXIS);  // another IMU's axis: a fault left uncured
  EXPECT_TRUE(outcomes.onOutcome(o));
  EXPECT_TRUE(outcomes.degraded());
}
