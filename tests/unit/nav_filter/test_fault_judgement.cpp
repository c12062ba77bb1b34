// The fault manager in the loop, as the bus delivers it: its commands answer a diagnostics
// epoch some time after the filter published it, and its progress reports (how far it has
// judged) travel on another writer. The deterministic output waits for each epoch's judgement,
// so every solution is the one `navbus offline` publishes (the command applied at once, in the
// diagnostics callback); a command that comes after its place anyway is merged by rewinding
// and leaves the full state as in time; a fault manager that stops reporting holds the output
// for its budget only.
#include <gtest/gtest.h>

#include <deque>
#include <utility>

#include "pipeline_runs.hpp"

using namespace navbus;
using namespace navbus::test;

namespace {

constexpr std::size_t kFrames = 1500;      // 15 s of data, GNSS at 1 Hz
constexpr std::size_t kDelayFrames = 150;  // the fault manager answers 1.5 s later
/// The diagnostics epoch the command answers (the sixth).
constexpr std::size_t kJudgedEpoch = 5;

FilterCommand compensateGyroX(std::uint64_t time_gps_ns) {
  FilterCommand c;
  c.command_id(1);
  c.vehicle_id(1);
  c.kind(CMD_COMPENSATE_BIAS);
  c.sensor(SOURCE_GYRO);
  c.axis(0);
  c.bias(2e-5);
  c.bias_sigma(1e-6);
  c.time_gps_ns(time_gps_ns);
  c.issuer("fault-manager");
  c.run_id(7);
  return c;
}

FilterCommand relearnAccelYFromOnset(std::uint64_t time_gps_ns) {
  FilterCommand c = compensateGyroX(time_gps_ns);
  c.kind(CMD_RELEARN_BIAS);
  c.sensor(SOURCE_ACCELEROMETER);
  c.axis(1);
  c.bias(0.0);
  c.bias_sigma(1e-3);
  c.onset_time_gps_ns(time_gps_ns - 3'000'000'000);
  return c;
}

FaultMonitorProgress progress(const FilterDiagnostics& d, std::uint64_t last_command_id) {
  FaultMonitorProgress p;
  p.vehicle_id(1);
  p.judged_up_to_gps_ns(d.time_gps_ns());
  p.diagnostics_seq(d.seq());
  p.last_command_id(last_command_id);
  p.issuer("fault-manager");
  p.run_id(7);
  return p;
}

/// The reference: the command applied within the callback of the epoch it answers, as
/// `navbus offline` runs the fault manager.
void answerInTime(FilterRun& run, FilterCommand (*make)(std::uint64_t),
                  std::size_t epoch = kJudgedEpoch) {
  run.on_diagnostics = [&run, make, epoch](const FilterDiagnostics& d) {
    if (run.diagnostics.size() == epoch + 1) run.pipeline->onCommand(make(d.time_gps_ns()));
  };
}

/// A fault manager on the bus: it judges every epoch and answers kDelayFrames later, the
/// command of the judged epoch `command_first_by` frames before (negative: after) its report.
struct DelayedMonitor {
  FilterRun& run;
  FilterCommand (*make)(std::uint64_t);
  long command_first_by{0};
  std::size_t delay_frames{kDelayFrames};
  std::size_t answered_epoch{kJudgedEpoch};  ///< the diagnostics epoch the command answers
  std::deque<std::pair<std::size_t, std::function<void()>>> due;  ///< frame, delivery

  void attach() {
    run.on_diagnostics = [this](const FilterDiagnostics& d) {
      const std::size_t at = frameNow + delay_frames;
      const bool answers = run.diagnostics.size() == answered_epoch + 1;
      const std::uint64_t last_id = run.diagnostics.size() > answered_epoch ? 1 : 0;
      if (answers) {
        const FilterCommand c = make(d.time_gps_ns());
        schedule(static_cast<std::size_t>(static_cast<long>(at) - command_first_by),
                 [this, c] { run.pipeline->onCommand(c); });
      }
      schedule(at, [this, p = progress(d, last_id)] { run.pipeline->onFaultMonitorProgress(p); });
    };
    run.before_frame = [this](std::size_t k) {
      frameNow = k;
      for (auto it = due.begin(); it != due.end();) {
        if (it->first > k) {
          ++it;
          continue;
        }
        it->second();
        it = due.erase(it);
      }
    };
  }
  void schedule(std::size_t frame, std::function<void()> f) {
    due.emplace_back(frame, std::move(f));
  }
  std::size_t frameNow{0};
};

/// Solutions of two runs of the same length that differ in their bits.
std::size_t differingSolutions(const FilterRun& a, const FilterRun& b) {
  std::size_t differing = 0;
  for (std::size_t k = 0; k < a.solutions.size(); ++k)
    differing += sameBits(a.solutions[k], b.solutions[k]) ? 0 : 1;
  return differing;
}

void expectSameSolutions(const FilterRun& a, const FilterRun& b) {
  ASSERT_EQ(a.solutions.size(), b.solutions.size());
  EXPECT_EQ(differingSolutions(a, b), 0u) << "of " << a.solutions.size();
}

const std::string kMonitored =
    "fault_monitor: {participant: navbus-fault-manager, judgement_wait_s: 1000}\n";

}  // namespace

TEST(FaultJudgement, TheOutputWaitsForEachEpochsJudgementAndEqualsOffline) {
  const std::vector<Frame> all = frames(kFrames);
  const auto config = tightlyCoupled(40.0, kMonitored);
  for (const long command_first_by : {20L, 0L, -20L}) {  // the report may overtake the command
    FilterRun offline(config), bus(config);
    answerInTime(offline, compensateGyroX);
    DelayedMonitor monitor{bus, compensateGyroX, command_first_by, kDelayFrames, kJudgedEpoch, {}};
    monitor.attach();
    offline.play(all);
    bus.play(all);
    expectSameSolutions(offline, bus);
    expectSameEngine(offline.pipeline->engine(), bus.pipeline->engine());
    const std::string summary = bus.pipeline->summary();
    EXPECT_NE(summary.find("commands applied 1 refused 0"), std::string::npos) << summary;
    EXPECT_NE(summary.find(") late 0"), std::string::npos) << summary;
    EXPECT_NE(summary.find("beyond the budget 0"), std::string::npos) << summary;
    if (command_first_by < 0) {
      EXPECT_NE(summary.find("(before their command 1)"), std::string::npos) << summary;
    }
  }
}

TEST(FaultJudgement, WithoutWaitingTheOutputDiffersOnlyUntilTheCommandCame) {
  // Not monitored (no fault_monitor): nothing waits, the command comes 1.5 s after its place.
  const std::vector<Frame> all = frames(kFrames);
  const auto config = tightlyCoupled(40.0);
  FilterRun offline(config), bus(config);
  answerInTime(offline, compensateGyroX);
  DelayedMonitor monitor{bus, compensateGyroX, 0, kDelayFrames, kJudgedEpoch, {}};
  monitor.attach();
  offline.play(all);
  bus.play(all);
  ASSERT_EQ(offline.solutions.size(), bus.solutions.size());
  const std::size_t differing = differingSolutions(offline, bus);
  EXPECT_GT(differing, 0u) << "the test would not see a missing wait";
  EXPECT_LE(differing, kDelayFrames + 1) << "only those published before the command came";
  EXPECT_NE(bus.pipeline->summary().find(") late 1"), std::string::npos) << bus.pipeline->summary();
}

TEST(FaultJudgement, AJudgedEpochIsMonitoredWhateverTheParticipantsClockSaid) {
  // The participant finds the fault manager not alive for 3 s of frames (its reports came
  // late, the fault manager was stopped): the judgement came all the same, and the solutions
  // say what offline says, flags and integrity included.
  const std::vector<Frame> all = frames(kFrames);
  const auto config = tightlyCoupled(40.0, kMonitored);
  FilterRun offline(config), bus(config);
  answerInTime(offline, compensateGyroX);
  // Within an epoch (kDelayFrames would hold each epoch's successors for longer than an epoch,
  // and the last ones would only be flushed, unjudged, at the end of the data).
  DelayedMonitor monitor{bus, compensateGyroX, 0, 50, kJudgedEpoch, {}};
  monitor.attach();
  const auto deliver = bus.before_frame;
  bus.before_frame = [&bus, deliver](std::size_t k) {
    bus.pipeline->setFaultMonitorAlive(k < 400 || k >= 700);
    deliver(k);
  };
  offline.play(all);
  bus.play(all);
  ASSERT_EQ(offline.solutions.size(), bus.solutions.size());
  for (std::size_t k = 0; k < bus.solutions.size(); ++k) {
    const NavigationSolution& a = offline.solutions[k];
    const NavigationSolution& b = bus.solutions[k];
    ASSERT_TRUE(sameBits(a, b)) << "solution " << k;
    ASSERT_EQ(a.active_fault_flags(), b.active_fault_flags()) << "solution " << k;
    ASSERT_EQ(a.integrity(), b.integrity()) << "solution " << k;
    ASSERT_EQ(a.horizontal_protection_level_m(), b.horizontal_protection_level_m()) << k;
  }
  EXPECT_EQ(bus.solutions.back().active_fault_flags() & FAULT_NO_FAULT_MONITOR, 0u);
}

TEST(FaultJudgement, AMonitorExpectedFromTheStartIsWaitedForBeforeItsFirstReport) {
  // The fault manager answers the very first diagnostics epoch, 1.5 s later, before it has
  // reported anything (a replay as fast as the readers take it outruns its start).
  const std::vector<Frame> all = frames(kFrames);
  std::size_t differing_without = 0;
  for (const bool from_start : {true, false}) {
    const auto config = tightlyCoupled(
        40.0, std::string("fault_monitor: {participant: navbus-fault-manager, ") +
                  "judgement_wait_s: 1000, judged_from_start: " + (from_start ? "true" : "false") +
                  "}\n");
    FilterRun offline(config), bus(config);
    answerInTime(offline, compensateGyroX, 0);
    DelayedMonitor monitor{bus, compensateGyroX, 0, kDelayFrames, 0, {}};
    monitor.attach();
    offline.play(all);
    bus.play(all);
    ASSERT_EQ(offline.solutions.size(), bus.solutions.size());
    const std::size_t differing = differingSolutions(offline, bus);
    const std::string summary = bus.pipeline->summary();
    if (from_start) {
      EXPECT_EQ(differing, 0u) << summary;
      EXPECT_NE(summary.find(") late 0"), std::string::npos) << summary;
    } else {
      differing_without = differing;
    }
  }
  EXPECT_GT(differing_without, 0u) << "without it, the first judgement is not waited for";
}

TEST(FaultJudgement, AnEpochBetweenIncrementsIsMonitoredOnceItsDiagnosticsAreJudged) {
  // A real receiver's epochs fall between IMU increments: 4 ms after one here. The filter
  // diagnoses an epoch at its state's time, the increment before it, and the fault manager
  // reports that time judged; the solutions after it are under its watch.
  std::vector<Frame> all = frames(kFrames);
  for (Frame& frame : all)
    for (Sample& sample : frame)
      if (auto* epoch = std::get_if<GnssObservationEpoch>(&sample))
        epoch->time_gps_ns(epoch->time_gps_ns() + 4'000'000);
  FilterRun bus(tightlyCoupled(40.0, kMonitored));
  bus.on_diagnostics = [&bus](const FilterDiagnostics& d) {
    bus.pipeline->onFaultMonitorProgress(progress(d, 0));  // judged at once
  };
  bus.play(all);
  ASSERT_GT(bus.diagnostics.size(), 10u);
  EXPECT_EQ(bus.diagnostics.front().time_gps_ns() % 10'000'000, 0u) << "at an increment";
  std::size_t flagged = 0;
  for (const NavigationSolution& s : bus.solutions) {
    if (s.time_gps_ns() <= bus.diagnostics.front().time_gps_ns()) continue;
    flagged += (s.active_fault_flags() & FAULT_NO_FAULT_MONITOR) != 0 ? 1 : 0;
  }
  EXPECT_EQ(flagged, 0u) << "of " << bus.solutions.size();
}

class LateCommand : public ::testing::TestWithParam<FilterCommand (*)(std::uint64_t)> {};

TEST_P(LateCommand, GivesTheFullInTimeStateBitForBit) {
  const std::vector<Frame> all = frames(kFrames);
  const auto config = tightlyCoupled(40.0);
  FilterRun in_time(config), late(config);
  answerInTime(in_time, GetParam());
  DelayedMonitor monitor{late, GetParam(), 0, kDelayFrames, kJudgedEpoch, {}};
  monitor.attach();
  in_time.play(all);
  late.play(all);
  expectSameEngine(in_time.pipeline->engine(), late.pipeline->engine());
  EXPECT_NE(late.pipeline->summary().find("commands applied 1 refused 0"), std::string::npos)
      << late.pipeline->summary();
}

INSTANTIATE_TEST_SUITE_P(CompensateAndRelearnFromOnset, LateCommand,
                         ::testing::Values(&compensateGyroX, &relearnAccelYFromOnset));

TEST(FaultJudgement, AMonitorThatStopsReportingHoldsTheOutputForItsBudgetOnly) {
  const std::vector<Frame> all = frames(kFrames);
  const auto config = tightlyCoupled(
      40.0, "fault_monitor: {participant: navbus-fault-manager, judgement_wait_s: 0.5}\n");
  FilterRun reference(config), bus(config);
  bus.on_diagnostics = [&bus](const FilterDiagnostics& d) {
    if (bus.diagnostics.size() <= 2) bus.pipeline->onFaultMonitorProgress(progress(d, 0));
  };  // judges the first two epochs at once, then falls silent
  reference.play(all);
  bus.play(all);
  expectSameSolutions(reference, bus);  // nothing was commanded: the same solutions, later
  // ... but those after the last judged epoch are not under its watch, and say so.
  const std::uint64_t judged_ns = bus.diagnostics.at(1).time_gps_ns();
  const std::uint64_t next_epoch_ns = bus.diagnostics.at(2).time_gps_ns();
  for (const NavigationSolution& s : bus.solutions) {
    const bool unjudged = s.time_gps_ns() > next_epoch_ns;
    EXPECT_EQ((s.active_fault_flags() & FAULT_NO_FAULT_MONITOR) != 0, unjudged)
        << "solution at " << s.time_gps_ns() << ", epochs judged up to " << judged_ns;
    if (unjudged) {
      ASSERT_EQ(s.integrity(), INTEGRITY_NOT_MONITORED);
    }
  }
  const std::string summary = bus.pipeline->summary();
  EXPECT_NE(summary.find("judgements waited for beyond the budget 1"), std::string::npos)
      << "set aside once, not waited for at every epoch: " << summary;
  const std::string reference_summary = reference.pipeline->summary();
  const std::string timeouts = reference_summary.substr(
      reference_summary.find("sequencer timeouts"), std::string("sequencer timeouts 0,").size());
  EXPECT_NE(summary.find(timeouts), std::string::npos)
      << "no other stream set aside than at the reference's end of data: " << summary;
}

TEST(FaultJudgement, AReceiversJudgeThatStopsAdvancingHoldsTheOutputForItsBudgetOnce) {
  // A filter waiting for the cross-receiver test (fault_monitor.receivers_judged): the fault
  // manager keeps judging the diagnostics, but its receivers' judgement stops at the third epoch
  // (a receiver fell silent and the test waits for it). The next epoch is held for the budget,
  // then the judge is passed over, and not waited for again at every epoch while the reports
  // carry the same receivers' time; nothing was commanded, so the solutions are the reference's.
  const std::vector<Frame> all = frames(kFrames);
  const auto config =
      tightlyCoupled(40.0,
                     "fault_monitor: {participant: navbus-fault-manager, judgement_wait_s: 0.5, "
                     "receivers_judged: true}\n");
  FilterRun reference(config), bus(config);
  std::uint64_t gnss_judged_ns = 0;
  bus.on_diagnostics = [&](const FilterDiagnostics& d) {
    FaultMonitorProgress p = progress(d, 0);
    if (bus.diagnostics.size() <= 3) gnss_judged_ns = d.time_gps_ns() + 1'000'000'000;
    p.gnss_judged_up_to_gps_ns(gnss_judged_ns);
    bus.pipeline->onFaultMonitorProgress(p);
  };
  reference.on_diagnostics = [&](const FilterDiagnostics& d) {
    FaultMonitorProgress p = progress(d, 0);
    p.gnss_judged_up_to_gps_ns(d.time_gps_ns() + 1'000'000'000);  // judges every next epoch
    reference.pipeline->onFaultMonitorProgress(p);
  };
  reference.play(all);
  bus.play(all);
  expectSameSolutions(reference, bus);
  const auto passedOver = [](const std::string& summary) {
    const std::string key = "judgements waited for beyond the budget ";
    const std::size_t at = summary.find(key);
    return at == std::string::npos ? -1 : std::stoi(summary.substr(at + key.size()));
  };
  EXPECT_EQ(passedOver(bus.pipeline->summary()), 1)
      << "passed over once, not at every epoch: " << bus.pipeline->summary();
  EXPECT_EQ(passedOver(reference.pipeline->summary()), 0) << reference.pipeline->summary();
}

// A command with an estimated onset restores the latest snapshot before the onset, re-processes
// what came before the onset, applies the command there and re-processes the rest: the snapshot
// period sets only how much is re-processed, never the result (docs/results.md, memory: a longer
// period keeps fewer engine copies).
TEST(FaultRecovery, TheSnapshotPeriodChangesNothingButWhatIsReprocessed) {
  const std::vector<Frame> all = frames(kFrames);
  std::vector<std::unique_ptr<FilterRun>> runs;
  for (const double period_s : {1.0, 3.0, 7.0}) {
    auto config = tightlyCoupled(40.0);
    config.recovery_snapshot_period_ns = static_cast<std::int64_t>(period_s * 1e9);
    runs.push_back(std::make_unique<FilterRun>(config));
    // The twelfth epoch's command, its onset 3 s earlier: a snapshot of the running filter
    // before it with every period.
    answerInTime(*runs.back(), &relearnAccelYFromOnset, 12);
    runs.back()->play(all);
    const std::string summary = runs.back()->pipeline->summary();
    EXPECT_NE(summary.find("recoveries from onset 1 (onset beyond history 0)"), std::string::npos)
        << period_s << " s: " << summary;
  }
  for (std::size_t k = 1; k < runs.size(); ++k) {
    expectSameEngine(runs.front()->pipeline->engine(), runs[k]->pipeline->engine());
    expectSameSolutions(*runs.front(), *runs[k]);
  }
}

// The first snapshot is taken before the first input, when the engine is not yet initialized,
// so it cannot be restored; the next one is taken as soon as the engine is: a fault whose onset
// is in the first snapshot period (2 s into the data, the default period 5 s) is restored to.
TEST(FaultRecovery, AnOnsetInTheFirstSnapshotPeriodIsRestoredTo) {
  const std::vector<Frame> all = frames(kFrames);
  const auto config = tightlyCoupled(40.0);
  ASSERT_GT(config.recovery_snapshot_period_ns, 3'000'000'000);
  FilterRun run(config);
  answerInTime(run, &relearnAccelYFromOnset);  // the sixth epoch's command, onset 3 s before it
  run.play(all);
  const std::string summary = run.pipeline->summary();
  EXPECT_NE(summary.find("recoveries from onset 1 (onset beyond history 0)"), std::string::npos)
      << summary;
}
