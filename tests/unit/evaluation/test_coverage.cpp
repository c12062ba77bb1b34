// The honesty table's arithmetic (evaluation/coverage.hpp) and the regular outage schedule
// (evaluation/real_car_benchmark.hpp).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/evaluation/coverage.hpp"
#include "navbus/evaluation/real_car_benchmark.hpp"

namespace navbus::evaluation {
namespace {

TEST(Coverage, AConsistentIsotropicErrorGivesTheChiSquareShares) {
  // Given horizontal errors drawn with the sigma_h the solution claims (N and E each sigma_h /
  // sqrt 2), when tallied, then the shares are 1 - exp(-k^2) and the median ratio sqrt(ln 2).
  std::mt19937_64 rng(7);
  const double sigma_h = 2.0;
  std::normal_distribution<double> axis(0.0, sigma_h / std::sqrt(2.0));
  CoverageTally t;
  for (int i = 0; i < 200'000; ++i) t.add(std::hypot(axis(rng), axis(rng)), sigma_h, true);
  EXPECT_NEAR(t.insideShare(1), consistentShare(1), 0.005);
  EXPECT_NEAR(t.insideShare(2), consistentShare(2), 0.002);
  EXPECT_NEAR(t.insideShare(3), consistentShare(3), 0.0005);
  EXPECT_NEAR(t.medianRatio(), kConsistentMedianRatio, 0.01);
  EXPECT_EQ(t.flaggedShare(), 0.0);
}

TEST(Coverage, SigmasTwiceTooSmallShowAndFlaggedEpochsAreCountedApart) {
  // Given errors twice the claimed sigma, half of them flagged, one flagged far outside.
  CoverageTally t;
  t.add(2.0, 1.0, true);   // inside 2 and 3
  t.add(4.0, 1.0, false);  // outside 3, flagged
  t.add(0.5, 1.0, true);   // inside 1
  t.add(1.5, 0.0, false);  // no sigma: outside every bound
  EXPECT_DOUBLE_EQ(t.insideShare(1), 0.25);
  EXPECT_DOUBLE_EQ(t.insideShare(2), 0.5);
  EXPECT_DOUBLE_EQ(t.insideShare(3), 0.5);
  EXPECT_DOUBLE_EQ(t.medianRatio(), 0.5 * (2.0 + 4.0));
  EXPECT_DOUBLE_EQ(t.flaggedShare(), 0.5);
  EXPECT_DOUBLE_EQ(t.unflaggedInside3Share(), 1.0);
  EXPECT_NE(coverageRow("run", t, true).find("50.0"), std::string::npos);
  EXPECT_EQ(coverageCsvLine("run", "outages", t, false),
            "run,outages,4,0.2500,0.5000,0.5000,3.0000,,\n");
}

TEST(OutageSchedule, RegularOutagesUpToTheLogsEnd) {
  const auto o = outageSchedule({15.0, 45.0, 243298.499}, 243807.499);
  ASSERT_EQ(o.size(), 11u) << "the shipped drive_0708 list";
  EXPECT_DOUBLE_EQ(o.front().start_sow, 243298.499);
  EXPECT_DOUBLE_EQ(o.back().start_sow, 243298.499 + 10 * 45.0);
  EXPECT_DOUBLE_EQ(o.back().end_sow - o.back().start_sow, 15.0);
}

TEST(OutageSchedule, BadSchedulesNameTheirValues) {
  try {
    outageSchedule({20.0, 10.0, 1.0}, 100.0);
    FAIL() << "a period shorter than the outage";
  } catch (const bus::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("period 10 s"), std::string::npos) << e.what();
  }
  EXPECT_THROW(outageSchedule({5.0, 10.0, 200.0}, 100.0), bus::ConfigError);  // after the log
  EXPECT_THROW(outageSchedule({50.0, 60.0, 60.0}, 100.0), bus::ConfigError);  // none fits
}

}  // namespace
}  // namespace navbus::evaluation
