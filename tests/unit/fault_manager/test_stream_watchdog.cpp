// The fault manager's stream watchdog: one decision per transition, announced ends, deadline
// events confirmed by the stream's own silence.
#include <gtest/gtest.h>

#include "navbus/bus/topics.hpp"
#include "navbus/fault_manager/fault_pipeline.hpp"
#include "navbus/fault_manager/stream_watchdog.hpp"

using navbus::fault_manager::StreamKind;
using navbus::fault_manager::StreamWatchdog;

namespace {
constexpr std::int64_t kMs = 1'000'000;
using Participant = StreamWatchdog::WriterParticipant;
/// A sample alone / an element of a block, written by `p`.
StreamWatchdog::Source single(const Participant& p) {
  return {StreamWatchdog::Delivery::kSample, p};
}
StreamWatchdog::Source inBlock(const Participant& p) {
  return {StreamWatchdog::Delivery::kBlock, p};
}
const navbus::fault_manager::StreamKey kImu1{StreamKind::kImu, 1}, kFix1{StreamKind::kGnssFix, 1},
    kFix2{StreamKind::kGnssFix, 2};
}  // namespace

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

TEST(StreamWatchdog, AnEndToldByAnotherReaderAheadCoversTheSamplesStillToCome) {
  // The parity test's reliable reader takes unit 2's dispose after its last increment at data
  // time 2000 while the watchdog's own reader has delivered up to 1200 only (and unit 3's not
  // at all): the rest of both streams, up to 2000, still comes through the watchdog's reader
  // and is no new run that would fall silent and be declared lost (a replay under the
  // sanitizers: two units LOST 2 s after their end).
  StreamWatchdog w;
  const navbus::fault_manager::StreamKey unit2{StreamKind::kImu, 2}, unit3{StreamKind::kImu, 3};
  EXPECT_FALSE(w.onSample(unit2, 1200, 1 * kMs));
  EXPECT_TRUE(w.onEnded(unit2, 2000));
  EXPECT_FALSE(w.onEnded(unit3, 2000));  // not seen here yet: its end is kept all the same
  for (std::uint64_t t = 1300; t <= 2000; t += 100) {
    EXPECT_FALSE(w.onSample(unit2, t, 10 * kMs));
    EXPECT_FALSE(w.onSample(unit3, t, 10 * kMs));
  }
  EXPECT_FALSE(w.onDeadlineMissed(unit2, 3000 * kMs));
  EXPECT_FALSE(w.onDeadlineMissed(unit3, 3000 * kMs));
  EXPECT_TRUE(w.onTick(3000 * kMs).empty());
  EXPECT_EQ(w.onWritersGone(StreamKind::kImu, 3000 * kMs).size(), 0u);
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

TEST(StreamWatchdog, StreamPacedAheadOfRealTimeIsJudgedByItsWriterOnly) {
  // A replay at full speed: 10 s of 100 Hz data in 0.1 s of wall time, then the writer waits
  // for a slow reliable reader. Its silence is no loss; its writer going away is.
  constexpr std::int64_t kS = 1000 * kMs;
  StreamWatchdog w;
  const navbus::fault_manager::StreamKey imu{StreamKind::kImu, 1};
  for (int i = 0; i <= 1000; ++i)
    EXPECT_FALSE(w.onSample(imu, static_cast<std::uint64_t>(i) * 10 * kMs, i * 100'000));
  EXPECT_EQ(w.streamsAheadOfRealTime(), 1u);
  EXPECT_FALSE(w.onDeadlineMissed(imu, 1 * kS, 250 * kMs));
  EXPECT_TRUE(w.onTick(5 * kS).empty());
  EXPECT_EQ(w.deadlinesAheadOfRealTime(), 1u);
  EXPECT_EQ(w.onWritersGone(StreamKind::kImu, 6 * kS).size(), 1u);

  // The same stream in real time (data time and wall time advance together, a reception
  // delayed by a 1.5 s stall of this participant included) stays watched by its deadline.
  StreamWatchdog rt;
  for (int i = 0; i <= 1000; ++i) {
    const std::int64_t stall = i >= 300 && i < 450 ? (450 - i) * 10 * kMs : 0;
    EXPECT_FALSE(rt.onSample(imu, static_cast<std::uint64_t>(i) * 10 * kMs, i * 10 * kMs + stall));
  }
  EXPECT_EQ(rt.streamsAheadOfRealTime(), 0u);
  EXPECT_TRUE(rt.onDeadlineMissed(imu, 10 * kS + 250 * kMs, 250 * kMs));
}

TEST(StreamWatchdog, AStreamInBlocksIsJudgedByItsWriterOnlyFromItsFirstBlock) {
  // A replay of an imported drive starved of CPU from its start: its increments come in
  // blocks, but their data time has not run ahead of the wall clock yet when the writer waits
  // 0.47 s for a stopped reliable reader (CI, 2026-12-01). Blocks are written faster than real
  // time: that silence is no loss; the writer going away is.
  StreamWatchdog w;
  const navbus::fault_manager::StreamKey imu{StreamKind::kImu, 1};
  for (int i = 0; i < 64; ++i)  // one block of 64 increments at 100 Hz, handed over at 1 s
    EXPECT_FALSE(w.onSample(imu, static_cast<std::uint64_t>(i) * 10 * kMs, 1000 * kMs,
                            inBlock(Participant{})));
  EXPECT_EQ(w.streamsAheadOfRealTime(), 1u);
  EXPECT_FALSE(w.onDeadlineMissed(imu, 1470 * kMs, 250 * kMs));
  EXPECT_TRUE(w.onTick(3000 * kMs).empty());
  EXPECT_FALSE(w.isLost(imu));
  EXPECT_EQ(w.deadlinesAheadOfRealTime(), 1u);
  EXPECT_EQ(w.onWritersGone(StreamKind::kImu, 4000 * kMs).size(), 1u);

  // The same increments one by one, at that pace: a real-time stream, watched by its deadline.
  StreamWatchdog rt;
  for (int i = 0; i < 64; ++i)
    EXPECT_FALSE(rt.onSample(imu, static_cast<std::uint64_t>(i) * 10 * kMs, 1000 * kMs));
  EXPECT_EQ(rt.streamsAheadOfRealTime(), 0u);
  EXPECT_TRUE(rt.onDeadlineMissed(imu, 1470 * kMs, 250 * kMs));
}

TEST(StreamWatchdog, TheOtherStreamsOfAPacedWritersParticipantAreJudgedByTheirWriterToo) {
  // An imported drive replayed: its increments in blocks, its GNSS fixes one by one, from one
  // participant. The fixes, seen first, look like a real-time stream; once the increments come
  // in blocks, they too wait with the replay, and their silence is no loss. A receiver of
  // another participant stays watched by its deadline.
  const Participant replay{1, 2, 3}, live{4, 5, 6};
  StreamWatchdog w;
  const auto &imu = kImu1, &fix = kFix1, &other_fix = kFix2;
  EXPECT_FALSE(w.onSample(fix, 0, 1000 * kMs, single(replay)));
  EXPECT_FALSE(w.onSample(other_fix, 0, 1000 * kMs, single(live)));
  EXPECT_FALSE(w.onDeadlineMissed(fix, 1100 * kMs, 2000 * kMs));  // suspect: 0.1 s of silence
  EXPECT_FALSE(w.onDeadlineMissed(other_fix, 1100 * kMs, 2000 * kMs));
  EXPECT_EQ(w.unconfirmedDeadlines(), 2u);
  for (int i = 0; i < 64; ++i)
    EXPECT_FALSE(
        w.onSample(imu, static_cast<std::uint64_t>(i) * 10 * kMs, 1000 * kMs, inBlock(replay)));
  EXPECT_EQ(w.streamsAheadOfRealTime(), 2u);   // the increments, and the fixes with them
  EXPECT_EQ(w.onTick(3500 * kMs).size(), 1u);  // the suspicion of the fixes is dropped...
  EXPECT_FALSE(w.isLost(fix));
  EXPECT_TRUE(w.isLost(other_fix));  // ... the other participant's stays and is confirmed
  EXPECT_FALSE(w.onDeadlineMissed(fix, 4000 * kMs, 2000 * kMs));
  EXPECT_EQ(w.deadlinesAheadOfRealTime(), 1u);

  // A later stream of the paced participant is paced from its first sample.
  const navbus::fault_manager::StreamKey star{StreamKind::kStarTracker, 1};
  EXPECT_FALSE(w.onSample(star, 0, 5000 * kMs, single(replay)));
  EXPECT_EQ(w.streamsAheadOfRealTime(), 3u);
  EXPECT_FALSE(w.onDeadlineMissed(star, 8000 * kMs, 2000 * kMs));
  EXPECT_FALSE(w.isLost(star));
}

TEST(StreamWatchdog, AParticipantThatAnnouncedTheEndOfItsDataEndsOnlyItsOwnStreams) {
  // The compose demo under DDS Security: the simulator's disposes of its increments (in blocks)
  // and of its GNSS fixes never reached the best-effort watchdog readers; its health report
  // said ENDED. Its streams end: their writers' leaving is no loss, and its blocks still in
  // flight start no new run. Another participant's receiver is lost when its writers go.
  const Participant sim{1, 2, 3}, other{4, 5, 6};
  StreamWatchdog w;
  const auto &imu = kImu1, &fix = kFix1, &other_fix = kFix2;
  for (int i = 0; i < 30; ++i)
    EXPECT_FALSE(
        w.onSample(imu, static_cast<std::uint64_t>(i) * 10 * kMs, 1000 * kMs, inBlock(sim)));
  EXPECT_FALSE(w.onSample(fix, 0, 1000 * kMs, single(sim)));
  EXPECT_FALSE(w.onSample(other_fix, 0, 1000 * kMs, single(other)));
  EXPECT_TRUE(w.onParticipantEnded(Participant{}).empty());  // not known
  const auto ended = w.onParticipantEnded(sim);
  ASSERT_EQ(ended.size(), 2u);
  for (const auto& key : ended) {
    EXPECT_NE(key.sensor_id, 2u);
    EXPECT_TRUE(w.onEnded(key, w.lastTime(key)));
  }
  // A block taken after the report, later than the last one taken before it: no new run.
  EXPECT_FALSE(w.onSample(imu, 300 * kMs, 1100 * kMs, inBlock(sim)));
  EXPECT_EQ(w.lastTime(imu), 0u);
  EXPECT_TRUE(w.onWritersGone(StreamKind::kImu, 1500 * kMs).empty());
  const auto gone = w.onWritersGone(StreamKind::kGnssFix, 1500 * kMs);
  ASSERT_EQ(gone.size(), 1u);
  EXPECT_EQ(gone[0].key.sensor_id, 2u);
  EXPECT_TRUE(gone[0].lost);
  // The sensor's next run comes from a new participant: watched again.
  EXPECT_FALSE(w.onSample(imu, 0, 2000 * kMs, inBlock(other)));
  EXPECT_EQ(w.onWritersGone(StreamKind::kImu, 2500 * kMs).size(), 1u);
}

TEST(FaultPipelineStreams, AWritersAnnouncedEndIsNoLossAndItsBlocksStillInFlightNoGap) {
  // The simulator's health report (ENDED) taken before the last blocks its watchdog reader
  // still held: they count as accepted, with no sequence gap, and its writers' leaving then
  // is no loss (no decision, no command).
  navbus::bus::HealthCounters health("fault-manager-test");
  std::vector<navbus::FaultDecision> decisions;
  int commands = 0;
  navbus::fault_manager::FaultPipeline pipeline(
      navbus::fault_manager::FaultManagerConfig{}, health,
      {[&](const navbus::FaultDecision& d) { decisions.push_back(d); },
       [&](const navbus::FilterCommand&) { ++commands; }});
  const Participant sim{7, 8, 9};
  const StreamWatchdog::Source block = inBlock(sim);
  for (std::uint64_t seq = 1; seq <= 30; ++seq)
    pipeline.onStreamSample(StreamKind::kImu, 1, seq, seq * 10 * kMs, 1000 * kMs, block);
  EXPECT_EQ(pipeline.onWriterParticipantEnded(sim).size(), 1u);
  for (std::uint64_t seq = 31; seq <= 60; ++seq)
    pipeline.onStreamSample(StreamKind::kImu, 1, seq, seq * 10 * kMs, 1010 * kMs, block);
  const auto& imu = health.stream(navbus::bus::topic::kImuIncrement);
  EXPECT_EQ(imu.sensors.at(1).accepted, 60u);
  EXPECT_EQ(imu.sensors.at(1).sequence_gaps, 0u);
  pipeline.onWritersGone(StreamKind::kImu, 1500 * kMs);
  EXPECT_TRUE(decisions.empty());
  EXPECT_EQ(commands, 0);
  EXPECT_NE(pipeline.summary().find("streams ended as announced 1"), std::string::npos)
      << pipeline.summary();
}

TEST(StreamWatchdog, AfterItsOwnStallTheWatchdogBelievesOnlyWhatPersists) {
  // The fault manager stopped for 2 s: DDS then reports every writer's liveliness lost and
  // every deadline missed, though only this process was silent.
  StreamWatchdog w;
  const navbus::fault_manager::StreamKey imu{StreamKind::kImu, 1};
  const navbus::fault_manager::StreamKey gnss{StreamKind::kGnssObservations, 1};
  EXPECT_FALSE(w.onSample(imu, 100, 0));
  EXPECT_FALSE(w.onSample(gnss, 100, 0));
  const std::int64_t resumed = 2000 * kMs;
  w.resumedAfterStall(resumed);
  EXPECT_TRUE(w.onWritersGone(StreamKind::kImu, resumed + 1 * kMs).empty());
  EXPECT_TRUE(w.onWritersGone(StreamKind::kGnssObservations, resumed + 1 * kMs).empty());
  // The silence counts from the resumption: a deadline event now is only suspect.
  EXPECT_FALSE(w.onDeadlineMissed(imu, resumed + 2 * kMs, 250 * kMs));
  // The IMU's writer is heard again; the receiver's is not.
  w.onWritersAlive(StreamKind::kImu);
  EXPECT_FALSE(w.onSample(imu, 200, resumed + 5 * kMs));
  const auto events = w.onTick(resumed + StreamWatchdog::kLivelinessGraceNs);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].key.kind, StreamKind::kGnssObservations);
  EXPECT_TRUE(events[0].lost);
  EXPECT_FALSE(w.isLost(imu));
  EXPECT_EQ(w.staleLivelinessEvents(), 1u);
  // Outside a grace, a writer gone is believed at once.
  EXPECT_EQ(
      w.onWritersGone(StreamKind::kImu, resumed + 3 * StreamWatchdog::kLivelinessGraceNs).size(),
      1u);
}
