// The fixed-interval smoother's backward pass against the closed form of a random walk observed
// at both ends, the log's handling of a re-processed stretch, no smoothing across a restart, and
// the forward filter's records of its covariance jumps.
#include <gtest/gtest.h>

#include "navbus/core/filter/aiding_measurements.hpp"
#include "navbus/core/filter/integrated_filter.hpp"
#include "navbus/core/filter/rts_smoother.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/units.hpp"

namespace core = navbus::core;
namespace earth = navbus::core::earth;
namespace layout = navbus::core::layout;
namespace units = navbus::units;

namespace {

constexpr std::int64_t kStepNs = 100'000'000;

/// A north position that walks (variance q per step) from a start known to p0 and is measured
/// once more, with variance r, `steps` steps later: what the forward filter records.
struct RandomWalk {
  double p0{4.0}, q{0.25}, r{0.01};
  int steps{20};
  double start_error_m{3.0};  ///< the forward estimate minus the measurement at the end
  earth::Geodetic start{40.1 * units::kDeg, -105.15 * units::kDeg, 1580.0};

  std::vector<core::SmoothingRecord> records() const {
    std::vector<core::SmoothingRecord> out;
    for (int k = 0; k <= steps; ++k) {
      core::SmoothingRecord r0;
      r0.time_ns = k * kStepNs;
      r0.state.time_ns = r0.time_ns;
      r0.state.position = start;
      r0.accel_bias_mps2.setZero();
      r0.gyro_bias_radps.setZero();
      r0.active = core::maskOf({layout::kPos});
      r0.transition.setIdentity();
      r0.correction.setZero();
      const double predicted = p0 + k * q;
      r0.predicted = core::StateMatrix::Identity() * predicted;
      r0.covariance = r0.predicted;
      r0.continues = k > 0;
      if (k == steps) {  // the measurement: the error estimate fed back, and P(k|k)
        const double gain = predicted / (predicted + r);
        r0.correction[layout::kPos.index] = gain * start_error_m;
        r0.state.position = earth::offsetNed(start, {-gain * start_error_m, 0.0, 0.0});
        r0.covariance(0, 0) = (1.0 - gain) * predicted;
      }
      out.push_back(r0);
    }
    return out;
  }
};

double northOf(const core::SmoothedEpoch& e, const earth::Geodetic& from) {
  return earth::differenceNed(e.state.position, from)[0];
}

TEST(RtsSmoother, ARandomWalkObservedAtBothEndsIsSmoothedAsTheClosedFormSays) {
  const RandomWalk walk;
  const auto smoothed = core::smoothFixedInterval(walk.records());
  ASSERT_EQ(smoothed.size(), static_cast<std::size_t>(walk.steps + 1));
  const double total = walk.p0 + walk.steps * walk.q + walk.r;
  for (int k = 0; k <= walk.steps; ++k) {
    // E[x_k | both ends] moves toward the end measurement by (p0 + k q) / (p0 + N q + r) of
    // the difference; its variance is (p0 + k q) (1 - (p0 + k q) / (p0 + N q + r)).
    const double share = (walk.p0 + k * walk.q) / total;
    const auto& e = smoothed[static_cast<std::size_t>(k)];
    EXPECT_NEAR(northOf(e, walk.start), -share * walk.start_error_m, 1e-6) << k;
    EXPECT_NEAR(e.sigma[layout::kPos.index] * e.sigma[layout::kPos.index],
                (walk.p0 + k * walk.q) * (1.0 - share), 1e-9)
        << k;
    // The unobserved east position keeps the forward variance.
    EXPECT_NEAR(e.sigma[layout::kPos.index + 1], std::sqrt(walk.p0 + k * walk.q), 1e-9) << k;
  }
  EXPECT_TRUE(smoothed.front().smoothed);
  EXPECT_FALSE(smoothed.back().smoothed);  // the last record is the forward estimate
}

TEST(RtsSmoother, NothingIsSmoothedAcrossARestart) {
  const RandomWalk walk;
  auto records = walk.records();
  records[10].continues = false;  // the filter restarted at record 10
  std::uint64_t singular = 7;
  const auto smoothed = core::smoothFixedInterval(records, &singular);
  EXPECT_EQ(singular, 0u);
  for (int k = 0; k < 10; ++k) {
    EXPECT_EQ(northOf(smoothed[static_cast<std::size_t>(k)], walk.start), 0.0) << k;
  }
  EXPECT_FALSE(smoothed[9].smoothed);
  EXPECT_LT(northOf(smoothed[10], walk.start), -0.1);  // after the restart: smoothed
}

TEST(RtsSmoother, ASingularPredictionIsCountedAndNotSmoothedAcross) {
  const RandomWalk walk;
  auto records = walk.records();
  records[5].predicted(0, 0) = -1.0;
  std::uint64_t singular = 0;
  const auto smoothed = core::smoothFixedInterval(records, &singular);
  EXPECT_EQ(singular, 1u);
  EXPECT_EQ(northOf(smoothed[4], walk.start), 0.0);
  EXPECT_LT(northOf(smoothed[5], walk.start), -0.1);
}

TEST(SmoothingLog, ARewoundPassReplacesWhatTheAbandonedOneRecorded) {
  core::SmoothingLog log;
  core::SmoothingRecord r;
  for (int k = 0; k < 5; ++k) {
    r.time_ns = k * kStepNs;
    log.add(r, k == 0 ? -1 : k);
  }
  // A filter restored to its snapshot after record 1 records at 2.5 steps: 2, 3, 4 go.
  r.time_ns = 5 * kStepNs / 2;
  log.add(r, 2);
  ASSERT_EQ(log.records().size(), 3u);
  EXPECT_EQ(log.records().back().time_ns, 5 * kStepNs / 2);
  EXPECT_EQ(log.dropped(), 3u);
  // A filter that starts afresh drops what lies at or after its first record.
  r.time_ns = kStepNs;
  log.add(r, -1);
  EXPECT_EQ(log.records().size(), 2u);
  EXPECT_EQ(log.dropped(), 5u);
}

/// A parked car's filter that records for the smoother, and its position fixes.
struct RecordingFilter {
  core::SmoothingLog log;
  core::IntegratedFilter filter;
  core::NavState start;
  std::int64_t step{0};

  RecordingFilter() {
    start.time_ns = 1'400'000'000'000'000'000;
    start.position = {40.0966 * units::kDeg, -105.1474 * units::kDeg, 1580.0};
    core::FilterTuning t;
    t.gate_sigma = 0.0;
    filter.initialize(start, 0.0, 0.0, t,
                      core::maskOf({layout::kPos, layout::kVel, layout::kAtt, layout::kAccelBias,
                                    layout::kGyroBias}));
    filter.setSmoothingLog(&log);
  }
  void propagate() {
    core::ImuIncrement inc;
    inc.interval_s = 0.01;
    inc.time_ns = start.time_ns + (++step) * 10'000'000;
    inc.delta_vel_b_mps = Eigen::Vector3d(0.0, 0.0, -9.80 * inc.interval_s);
    filter.propagate(inc);
  }
  void update(double north_m = 0.05) {
    filter.update(core::positionMeasurement(
                      filter.state(), earth::offsetNed(start.position, {north_m, 0.0, 0.0}),
                      Eigen::Vector3d::Constant(0.02), Eigen::Vector3d::Zero()),
                  core::AidingKind::kPosition);
  }
};

constexpr int kNorth = layout::kPos.index;

TEST(SmoothingRecords, AJumpBeforeTheUpdatesIsInTheirPredictedCovariance) {
  RecordingFilter r;
  r.propagate();
  r.propagate();
  const core::StateMatrix propagated = r.filter.covariance();
  r.filter.addVariance(kNorth, 4.0);  // a stage switch's inflation, before the epoch's fix
  r.update();
  const core::StateMatrix updated = r.filter.covariance();
  r.propagate();  // records the epoch
  const core::SmoothingRecord& rec = r.log.records().back();
  EXPECT_EQ(rec.time_ns, r.start.time_ns + 2 * 10'000'000);
  EXPECT_NEAR(rec.predicted(kNorth, kNorth), propagated(kNorth, kNorth) + 4.0, 1e-12);
  EXPECT_NEAR(rec.covariance(kNorth, kNorth), updated(kNorth, kNorth), 1e-15);
  EXPECT_TRUE(rec.continues);
}

TEST(SmoothingRecords, AJumpBetweenTwoUpdatesOfAnEpochSplitsItIntoTwoRecords) {
  RecordingFilter r;
  r.propagate();
  const core::StateMatrix propagated = r.filter.covariance();
  r.update();  // e.g. a constraint at the increment
  const core::StateMatrix first = r.filter.covariance();
  const std::size_t before = r.log.records().size();
  r.filter.addVariance(kNorth, 4.0);              // the stage switch the fix then brings
  ASSERT_EQ(r.log.records().size(), before + 1);  // the updates so far: their own record
  r.update(0.10);  // this fix reads 5 cm further north: the estimate (error) moves
  const core::StateMatrix second = r.filter.covariance();
  r.propagate();
  ASSERT_EQ(r.log.records().size(), before + 2);
  const core::SmoothingRecord& a = r.log.records()[before];
  const core::SmoothingRecord& b = r.log.records()[before + 1];
  EXPECT_EQ(a.time_ns, b.time_ns);
  EXPECT_NEAR(a.predicted(kNorth, kNorth), propagated(kNorth, kNorth), 1e-15);
  EXPECT_NEAR(a.covariance(kNorth, kNorth), first(kNorth, kNorth), 1e-15);
  // Between the two: no motion, the jump as process noise.
  EXPECT_TRUE(b.transition.isIdentity(0.0));
  EXPECT_NEAR(b.predicted(kNorth, kNorth), first(kNorth, kNorth) + 4.0, 1e-12);
  EXPECT_NEAR(b.predicted(kNorth + 1, kNorth + 1), first(kNorth + 1, kNorth + 1), 1e-15);
  EXPECT_NEAR(b.covariance(kNorth, kNorth), second(kNorth, kNorth), 1e-15);
  EXPECT_TRUE(b.continues);
  EXPECT_LT(b.correction[kNorth], -0.02);  // the second fix's share of its 5 cm, its own
  // The smoothed run has one epoch per time: the later record's.
  r.filter.closeSmoothingRecord();
  const auto smoothed = core::smoothFixedInterval(r.log.records());
  EXPECT_EQ(smoothed.size(), r.log.records().size() - 1);
  for (std::size_t k = 1; k < smoothed.size(); ++k)
    EXPECT_LT(smoothed[k - 1].time_ns, smoothed[k].time_ns) << k;
}

TEST(SmoothingRecords, AResetNoNoiseGivesIsNotSmoothedAcross) {
  RecordingFilter r;
  r.propagate();
  r.update();
  const std::size_t before = r.log.records().size();
  r.filter.resetVariances(layout::kVel, 0.01);  // the paper's reset: variances set
  r.propagate();
  r.update();
  r.propagate();
  const auto& records = r.log.records();
  ASSERT_EQ(records.size(), before + 2);
  EXPECT_TRUE(records[before].continues);  // the epoch before the reset, with its update
  EXPECT_FALSE(records[before + 1].continues);
}

}  // namespace
