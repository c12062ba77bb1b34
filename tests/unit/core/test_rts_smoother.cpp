// The fixed-interval smoother's backward pass against the closed form of a random walk observed
// at both ends, the log's handling of a re-processed stretch, and no smoothing across a restart.
#include <gtest/gtest.h>

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
    log.add(r, k == 0 ? -1 : (k - 1) * kStepNs);
  }
  // A filter restored to its snapshot after record 1 records at 2.5 steps: 2, 3, 4 go.
  r.time_ns = 5 * kStepNs / 2;
  log.add(r, kStepNs);
  ASSERT_EQ(log.records().size(), 3u);
  EXPECT_EQ(log.records().back().time_ns, 5 * kStepNs / 2);
  EXPECT_EQ(log.dropped(), 3u);
  // A filter that starts afresh drops what lies at or after its first record.
  r.time_ns = kStepNs;
  log.add(r, -1);
  EXPECT_EQ(log.records().size(), 2u);
  EXPECT_EQ(log.dropped(), 5u);
}

}  // namespace
