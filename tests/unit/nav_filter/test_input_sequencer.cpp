// The filter's ordered merge (InputSequencer): time order whatever the arrival order, bounded
// waits for slow streams, lost streams set aside.
#include <gtest/gtest.h>

#include "navbus/nav_filter/input_sequencer.hpp"

using navbus::nav_filter::InputSequencer;
using navbus::nav_filter::StreamId;
using Seq = InputSequencer<int>;

namespace {
constexpr std::int64_t kMs = 1'000'000;
const StreamId kImu{0, 1};
const StreamId kGnss{1, 1};

std::vector<std::pair<std::int64_t, int>> drain(Seq& s, std::int64_t now) {
  std::vector<std::pair<std::int64_t, int>> out;
  s.release(now, [&](StreamId, std::int64_t t, const int& v) { out.emplace_back(t, v); });
  return out;
}
}  // namespace

TEST(InputSequencer, OrdersByTimeThenRankWhateverTheArrivalOrder) {
  // Given a 100 Hz IMU and a 1 Hz receiver, delivered in two different interleavings,
  // when everything has arrived, then both release the same sequence.
  auto run = [](bool gnss_first) {
    Seq s({{kImu, 10 * kMs}, {kGnss, 1000 * kMs}}, 500 * kMs);
    std::vector<std::pair<std::int64_t, int>> out;
    auto push_imu = [&](int k) { s.push(kImu, k * 10 * kMs, k); };
    if (gnss_first) {
      s.push(kGnss, 0, -1);
      s.push(kGnss, 1000 * kMs, -2);
    }
    for (int k = 0; k <= 100; ++k) {
      push_imu(k);
      auto part = drain(s, 0);
      out.insert(out.end(), part.begin(), part.end());
      if (!gnss_first && k == 0) s.push(kGnss, 0, -1);
      if (!gnss_first && k == 100) s.push(kGnss, 1000 * kMs, -2);
    }
    s.push(kImu, 1010 * kMs, 101);
    auto part = drain(s, 0);
    out.insert(out.end(), part.begin(), part.end());
    return out;
  };
  const auto a = run(true);
  const auto b = run(false);
  EXPECT_EQ(a, b);
  ASSERT_GE(a.size(), 103u);
  // At t = 1 s the increment (rank 0) comes before the receiver epoch (rank 1).
  for (std::size_t i = 1; i < a.size(); ++i) EXPECT_LE(a[i - 1].first, a[i].first);
  const auto at1s = std::find(a.begin(), a.end(), std::make_pair(1000 * kMs, 100));
  ASSERT_NE(at1s, a.end());
  EXPECT_EQ(*(at1s + 1), std::make_pair(1000 * kMs, -2));
}

TEST(InputSequencer, WaitsForASlowStreamOnlyUntilItsPromisedNextSample) {
  Seq s({{kImu, 10 * kMs}, {kGnss, 1000 * kMs}}, 500 * kMs);
  s.push(kGnss, 0, -1);
  s.push(kImu, 990 * kMs, 1);  // before the receiver's next epoch (1 s): released at once
  EXPECT_EQ(drain(s, 0).size(), 2u);
  s.push(kImu, 1010 * kMs, 2);  // after it: held
  EXPECT_TRUE(drain(s, 0).empty());
  EXPECT_TRUE(drain(s, 499 * kMs).empty());
  // Bounded wait: released after max_wait, the silent stream is set aside, counted.
  EXPECT_EQ(drain(s, 501 * kMs).size(), 1u);
  EXPECT_EQ(s.timeouts(), 1u);
  s.push(kImu, 1020 * kMs, 3);
  EXPECT_EQ(drain(s, 502 * kMs).size(), 1u);  // no new wait while the stream is silent
  // The late epoch is refused: its place in the order has passed.
  EXPECT_EQ(s.push(kGnss, 1000 * kMs, -2), Seq::PushResult::kLate);
  EXPECT_EQ(s.push(StreamId{0, 9}, 1030 * kMs, 4), Seq::PushResult::kUnexpected);
}

TEST(InputSequencer, AStreamDeclaredLostDoesNotHoldOthers) {
  Seq s({{kImu, 10 * kMs}, {kGnss, 1000 * kMs}}, 500 * kMs);
  s.setActive(kGnss, false);
  s.push(kImu, 10 * kMs, 1);
  EXPECT_EQ(drain(s, 0).size(), 1u);
  EXPECT_EQ(s.timeouts(), 0u);
}

TEST(InputSequencer, ABacklogWithinTheReserveAllocatesNothingABiggerOneIsCounted) {
  // A backlog after the filter was starved: 200 IMU samples arrive at once while the receiver
  // holds them back (its next epoch not yet here). Within the reserve the buffer does not grow;
  // the same backlog with a smaller reserve grows it, and that is counted.
  const auto backlog = [](std::size_t reserve) {
    Seq s({{kImu, 10 * kMs}, {kGnss, 1000 * kMs}}, 500 * kMs);
    s.reserve(reserve);
    s.push(kGnss, 0, -1);
    for (int k = 0; k < 200; ++k) s.push(kImu, k * 10 * kMs, k);
    const std::size_t released = drain(s, 0).size();  // up to the receiver's next promise
    EXPECT_EQ(released + s.pending(), 201u);
    return s.grown();
  };
  EXPECT_EQ(backlog(256), 0u);
  EXPECT_GE(backlog(64), 1u);
}
