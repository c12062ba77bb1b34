// Participant logic without DDS: the filter's input sequencer, the stream watchdog, the
// tool's formatters.
#include <gtest/gtest.h>

#include "navbus/fault_manager/stream_watchdog.hpp"
#include "navbus/nav_filter/input_sequencer.hpp"
#include "navbus/records/formatters.hpp"

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

using navbus::fault_manager::StreamKind;
using navbus::fault_manager::StreamWatchdog;

TEST(StreamWatchdog, OneDecisionPerTransition) {
  StreamWatchdog w;
  const navbus::fault_manager::StreamKey imu{StreamKind::kImu, 1};
  EXPECT_FALSE(w.onDeadlineMissed(imu, 0));  // never seen: nothing to lose
  EXPECT_FALSE(w.onSample(imu, 100, 1 * kMs));
  auto lost = w.onDeadlineMissed(imu, 251 * kMs);
  ASSERT_TRUE(lost);
  EXPECT_TRUE(lost->lost);
  EXPECT_EQ(lost->last_time_gps_ns, 100u);
  EXPECT_NEAR(lost->silence_s, 0.25, 1e-9);
  EXPECT_FALSE(w.onDeadlineMissed(imu, 501 * kMs));  // repeated misses: no new decision
  EXPECT_TRUE(w.onWritersGone(StreamKind::kImu, 600 * kMs).empty());
  auto back = w.onSample(imu, 5000, 2000 * kMs);
  ASSERT_TRUE(back);
  EXPECT_FALSE(back->lost);
  EXPECT_EQ(back->last_time_gps_ns, 5000u);
  EXPECT_FALSE(w.isLost(imu));
  // Writers gone: every alive stream of that kind is lost at once.
  w.onSample({StreamKind::kImu, 2}, 1, 2000 * kMs);
  EXPECT_EQ(w.onWritersGone(StreamKind::kImu, 2100 * kMs).size(), 2u);
}

TEST(StreamWatchdog, SamplesInFlightAfterAnAnnouncedEndAreNoNewRun) {
  // The raw stream ends with the IMU's dispose at data time 1000; a reliable reader may still
  // deliver raw blocks up to that time afterwards: they must not start a run that then
  // "falls silent" (the demo's end-of-data false alarm).
  StreamWatchdog w;
  const navbus::fault_manager::StreamKey raw{StreamKind::kImuRaw, 1};
  EXPECT_FALSE(w.onSample(raw, 900, 1 * kMs));
  EXPECT_TRUE(w.onEnded(raw, 1000));
  EXPECT_FALSE(w.onSample(raw, 950, 2 * kMs));
  EXPECT_FALSE(w.onSample(raw, 1000, 3 * kMs));
  EXPECT_FALSE(w.onDeadlineMissed(raw, 300 * kMs));
  EXPECT_FALSE(w.onEnded(raw));  // nothing running
  // A later sample is a new run of the stream, watched again.
  EXPECT_FALSE(w.onSample(raw, 5000, 400 * kMs));
  EXPECT_EQ(w.lastTime(raw), 5000u);
  EXPECT_TRUE(w.onDeadlineMissed(raw, 700 * kMs));
}

TEST(StreamWatchdog, DeadlineEventIsConfirmedByTheOwnSilence) {
  // Under CPU load DDS's deadline timer (from reception) can fire before this participant has
  // been silent for the deadline by its own clock (from the hand-over): the stream is only
  // suspect then; the tick declares it once the own silence reaches the deadline, and a sample
  // before that clears it.
  StreamWatchdog w;
  const navbus::fault_manager::StreamKey imu{StreamKind::kImu, 1};
  const std::int64_t deadline = 250 * kMs;
  EXPECT_FALSE(w.onSample(imu, 100, 1000 * kMs));
  EXPECT_FALSE(w.onDeadlineMissed(imu, 1247 * kMs, deadline));  // silent 0.247 s < 0.25 s
  EXPECT_EQ(w.unconfirmedDeadlines(), 1u);
  EXPECT_TRUE(w.onTick(1249 * kMs).empty());
  const auto lost = w.onTick(1250 * kMs);
  ASSERT_EQ(lost.size(), 1u);
  EXPECT_TRUE(lost[0].lost);
  EXPECT_NEAR(lost[0].silence_s, 0.25, 1e-9);
  EXPECT_TRUE(w.onTick(1300 * kMs).empty());  // once
  // A sample clears a suspect stream: the delayed hand-over was no silence.
  EXPECT_TRUE(w.onSample(imu, 200, 1400 * kMs));  // restored
  EXPECT_FALSE(w.onDeadlineMissed(imu, 1640 * kMs, deadline));
  EXPECT_FALSE(w.onSample(imu, 300, 1645 * kMs));
  EXPECT_TRUE(w.onTick(1900 * kMs).empty());
  EXPECT_FALSE(w.isLost(imu));
}

TEST(Formatters, CsvHasOneRowPerSatelliteAndRoundTripsDoubles) {
  navbus::GnssObservationEpoch e;
  e.receiver_id(3);
  e.time_gps_ns(42);
  for (int sv : {4, 9}) {
    navbus::GnssSatelliteMeasurement m;
    m.sv_id(static_cast<std::uint16_t>(sv));
    m.pseudorange_m(20000000.125);
    e.satellites().push_back(m);
  }
  const std::string header = navbus::records::csvHeader<navbus::GnssObservationEpoch>();
  EXPECT_EQ(
      header.rfind("receiver_id,seq,time_gps_ns,satellites.sv_id,satellites.pseudorange_m", 0), 0u);
  const auto rows = navbus::records::csvRows(e);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].rfind("3,0,42,9,20000000.125", 0), 0u);
  navbus::Health h;
  h.participant("navbus-filter");
  h.state(navbus::STATE_DEGRADED);
  const auto hr = navbus::records::csvRows(h);
  ASSERT_EQ(hr.size(), 1u);  // no inputs: one row with empty input cells
  EXPECT_EQ(hr[0].rfind("navbus-filter,0,0,DEGRADED,0", 0), 0u);
  // Shortest text that reads back to the same bits.
  for (const double v :
       {0.1 + 0.2, 0.00980665, 9.80665 / 1000.0, 1e-300, -3000.0, 6378137.0, 1.1309733552923256}) {
    const std::string text = navbus::records::formatNumber(v);
    EXPECT_EQ(std::stod(text), v) << text;
  }
  EXPECT_EQ(navbus::records::formatNumber(0.00980665), "0.00980665");
  EXPECT_EQ(navbus::records::formatNumber(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(navbus::records::formatNumber(3000.0), "3000");
}
