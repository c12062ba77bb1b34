// Repeated decisions on one fault source escalate once, and an escalated source is not
// decided again: the fault loop cannot storm.
#include <gtest/gtest.h>

#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/repeat_guard.hpp"

using navbus::fault_manager::FaultSourceKey;
using navbus::fault_manager::RepeatGuard;
using Verdict = RepeatGuard::Verdict;

namespace {
constexpr std::int64_t kS = 1'000'000'000;
const FaultSourceKey kAccelY{5, 0, 1}, kGyroX{6, 0, 0}, kSv13{7, 13, 0};
}  // namespace

TEST(RepeatGuard, TheThirdDecisionOnASourceWithinTheWindowEscalatesThenNothingMore) {
  RepeatGuard g({300.0, 2});
  EXPECT_EQ(g.onDetection(100 * kS, {kAccelY, kGyroX}), Verdict::kDecide);
  EXPECT_EQ(g.onDetection(150 * kS, {kAccelY}), Verdict::kDecide);
  EXPECT_EQ(g.onDetection(200 * kS, {kGyroX, kAccelY}), Verdict::kEscalate);
  for (int k = 0; k < 50; ++k)
    EXPECT_EQ(g.onDetection((202 + 2 * k) * kS, {kAccelY, kGyroX}), Verdict::kSuppress);
  EXPECT_EQ(g.onDetection(400 * kS, {kGyroX}), Verdict::kSuppress) << "escalated with accel y";
  EXPECT_EQ(g.escalations(), 1u);
  EXPECT_EQ(g.suppressed(), 51u);
  // Another source is decided as configured.
  EXPECT_EQ(g.onDetection(410 * kS, {kSv13}), Verdict::kDecide);
}

TEST(RepeatGuard, DecisionsOlderThanTheWindowDoNotCount) {
  RepeatGuard g({100.0, 2});
  EXPECT_EQ(g.onDetection(0, {kSv13}), Verdict::kDecide);
  EXPECT_EQ(g.onDetection(50 * kS, {kSv13}), Verdict::kDecide);
  EXPECT_EQ(g.onDetection(120 * kS, {kSv13}), Verdict::kDecide);  // the first has left
  EXPECT_EQ(g.onDetection(130 * kS, {kSv13}), Verdict::kEscalate);
}

TEST(RepeatGuard, ConfiguredUnderGlrRepeats) {
  const auto c = navbus::fault_manager::parseFaultManagerConfig(
      YAML::Load("glr: {repeats: {window_s: 90, escalate_after: 3}}"));
  EXPECT_EQ(c.glr.repeats.window_s, 90.0);
  EXPECT_EQ(c.glr.repeats.escalate_after, 3);
  EXPECT_THROW(navbus::fault_manager::parseFaultManagerConfig(
                   YAML::Load("glr: {repeats: {escalate_after: 0}}")),
               std::exception);
}
