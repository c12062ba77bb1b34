// The consistency monitor's false-alarm rate on a consistent filter is what it was designed
// for, and a filter whose innovations outgrow its covariance is caught and re-initialised.
#include <gtest/gtest.h>

#include <random>

#include "navbus/core/integrity/consistency_monitor.hpp"
#include "navbus/core/integrity/fix_innovation_log.hpp"

using navbus::core::ConsistencyConfig;
using navbus::core::ConsistencyMonitor;

namespace {

constexpr std::int64_t kEpochNs = 1'000'000'000;
constexpr int kEpochRows = 16;

/// `epochs` epochs of kEpochRows normalized innovations scaled by `scale` (1: consistent).
ConsistencyMonitor feed(const ConsistencyConfig& config, int epochs, double scale, unsigned seed) {
  ConsistencyMonitor m;
  m.configure(config);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, scale);
  for (int k = 0; k < epochs; ++k) {
    double nis = 0.0;
    for (int i = 0; i < kEpochRows; ++i) {
      const double v = n(rng);
      nis += v * v;
    }
    m.onEpoch(k * kEpochNs, nis, kEpochRows);
  }
  return m;
}

}  // namespace

TEST(ConsistencyMonitor, AlarmsOnAConsistentFilterAtItsDesignRate) {
  ConsistencyConfig c;
  c.window_epochs = 10;
  c.false_alarm_probability = 0.01;
  const ConsistencyMonitor m = feed(c, 200000, 1.0, 7);
  const double rate = static_cast<double>(m.counters().epochs_inconsistent) /
                      static_cast<double>(m.counters().epochs_tested);
  EXPECT_GT(rate, 0.005);  // the test is not blind ...
  EXPECT_LT(rate, 0.015);  // ... and alarms as often as designed (200,000 epochs: +-0.001)
}

TEST(ConsistencyMonitor, InnovationsLargerThanTheCovarianceSaysAreCaughtAndReinitialised) {
  ConsistencyConfig c;
  c.window_epochs = 10;
  c.false_alarm_probability = 1e-4;
  c.reinitialise_after_s = 5.0;
  ConsistencyMonitor m = feed(c, 30, 2.0, 11);  // twice the sigma the filter claims
  EXPECT_TRUE(m.inconsistent());
  EXPECT_TRUE(m.reinitialisationDue());
  EXPECT_EQ(m.counters().alarms, 1u);
  EXPECT_EQ(m.counters().reinitialisations, 1u);
  m.restart();
  EXPECT_FALSE(m.inconsistent());
  EXPECT_FALSE(m.reinitialisationDue());
}

TEST(ConsistencyMonitor, ABriefExcessAlarmsWithoutAskingForReinitialisation) {
  ConsistencyConfig c;
  c.window_epochs = 5;
  c.false_alarm_probability = 1e-4;
  c.reinitialise_after_s = 10.0;
  ConsistencyMonitor m;
  m.configure(c);
  for (int k = 0; k < 40; ++k) {
    const double nis = (k >= 20 && k < 22) ? 400.0 : kEpochRows;  // two bad epochs
    m.onEpoch(k * kEpochNs, nis, kEpochRows);
  }
  EXPECT_EQ(m.counters().alarms, 1u);
  EXPECT_EQ(m.counters().reinitialisations, 0u);
  EXPECT_FALSE(m.inconsistent());
}

TEST(ConsistencyMonitor, DisabledOrEmptyEpochsTestNothing) {
  ConsistencyConfig c;
  c.enabled = false;
  EXPECT_EQ(feed(c, 100, 3.0, 1).counters().epochs_tested, 0u);
  ConsistencyMonitor m;
  m.configure(ConsistencyConfig{});
  for (int k = 0; k < 100; ++k) m.onEpoch(k * kEpochNs, 0.0, 0);
  EXPECT_EQ(m.counters().epochs_tested, 0u);
}

TEST(FixInnovationLog, ARewoundPassReplacesWhatTheAbandonedOneRecorded) {
  navbus::core::FixInnovationLog log;
  navbus::core::FixInnovation f;
  for (int k = 0; k < 5; ++k) {
    f.time_ns = k * 250'000'000;
    log.add(f);
  }
  // Re-processed from 0.6 s: the fixes of 0.75 and 1.0 s go, and come again.
  f.time_ns = 750'000'000;
  log.add(f);
  EXPECT_EQ(log.records().size(), 4u);
  EXPECT_EQ(log.dropped(), 2u);
  f.time_ns = 1'000'000'000;
  log.add(f);
  EXPECT_EQ(log.records().size(), 5u);
  EXPECT_EQ(log.dropped(), 2u);
}
