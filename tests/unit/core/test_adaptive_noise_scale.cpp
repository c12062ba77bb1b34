// Bounded adaptive measurement noise (covariance matching): on a Kalman filter whose
// measurements are noisier than they say by a known factor, the scale converges to that
// factor; it never leaves its floor and ceiling; an epoch's own rows never change the scale it
// was fused with; disabled, it stays at 1.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "navbus/core/filter/adaptive_noise_scale.hpp"

using navbus::core::NoiseScaleConfig;
using navbus::core::NoiseScaleEstimator;
using navbus::core::scalarUpdate;
using navbus::core::ScalarUpdateResult;

namespace {

constexpr double kNominalSigma = 0.5;  ///< what the stream says its noise is [m]
constexpr int kRowsPerEpoch = 3;

struct ScaleTrack {
  double mean_last{0.0};  ///< mean scale over the last quarter of the run
  double min{1e300}, max{0.0};
};

/// A random walk of 0.2 m/sqrt(epoch) measured directly, kRowsPerEpoch rows per epoch, with
/// noise sigma kNominalSigma * sqrt(true_scale); the filter uses the estimator's scale on the
/// nominal variance and whitens each row as ErrorState::update does.
ScaleTrack runScalarFilter(const NoiseScaleConfig& config, double true_scale, int epochs,
                           unsigned seed) {
  NoiseScaleEstimator est;
  est.configure(config);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  Eigen::Matrix<double, 1, 1> x = Eigen::Matrix<double, 1, 1>::Zero();
  Eigen::Matrix<double, 1, 1> P = Eigen::Matrix<double, 1, 1>::Constant(1.0);
  const Eigen::Matrix<double, 1, 1> h = Eigen::Matrix<double, 1, 1>::Ones();
  const double q = 0.04;
  double truth = 0.0;
  ScaleTrack track;
  int counted = 0;
  for (int k = 0; k < epochs; ++k) {
    truth += std::sqrt(q) * unit(rng);
    P(0, 0) += q;
    const double sigma_used = kNominalSigma * std::sqrt(est.scale());
    for (int i = 0; i < kRowsPerEpoch; ++i) {
      const double z = truth + kNominalSigma * std::sqrt(true_scale) * unit(rng);
      // Whitened: z / sigma against h / sigma, unit variance (the error-state filter's form).
      Eigen::Matrix<double, 1, 1> xw = x / sigma_used;
      Eigen::Matrix<double, 1, 1> Pw = P / (sigma_used * sigma_used);
      const ScalarUpdateResult r = scalarUpdate<1>(xw, Pw, h, z / sigma_used, 1.0, 0.0);
      x = xw * sigma_used;
      P = Pw * sigma_used * sigma_used;
      est.addRow(r);
    }
    est.closeEpoch();
    track.min = std::min(track.min, est.scale());
    track.max = std::max(track.max, est.scale());
    if (k >= 3 * epochs / 4) {
      track.mean_last += est.scale();
      ++counted;
    }
  }
  track.mean_last /= counted;
  return track;
}

NoiseScaleConfig enabled(int window, double floor, double ceiling) {
  NoiseScaleConfig c;
  c.enabled = true;
  c.window_epochs = window;
  c.floor = floor;
  c.ceiling = ceiling;
  return c;
}

}  // namespace

TEST(AdaptiveNoiseScale, ConvergesOnAKnownNoiseScale) {
  for (const double true_scale : {0.5, 1.0, 2.5, 6.0}) {
    const ScaleTrack t = runScalarFilter(enabled(40, 0.1, 20.0), true_scale, 4000, 7);
    // 40 epochs x 3 rows: the window's mean scatters by about sqrt(2 / 120) = 13 %; the mean of
    // the last 1000 epochs (25 independent windows) by under 3 %.
    EXPECT_NEAR(t.mean_last / true_scale, 1.0, 0.08) << "true scale " << true_scale;
  }
}

TEST(AdaptiveNoiseScale, StaysBetweenItsFloorAndCeiling) {
  const ScaleTrack noisy = runScalarFilter(enabled(10, 1.0, 4.0), 25.0, 2000, 11);
  EXPECT_DOUBLE_EQ(noisy.max, 4.0);  // 25 times noisier than it says: held at the ceiling
  EXPECT_DOUBLE_EQ(noisy.mean_last, 4.0);
  const ScaleTrack quiet = runScalarFilter(enabled(10, 1.0, 4.0), 0.2, 2000, 12);
  EXPECT_DOUBLE_EQ(quiet.min, 1.0);  // quieter than it says: never below the stream's own R
  EXPECT_DOUBLE_EQ(quiet.mean_last, 1.0);
}

TEST(AdaptiveNoiseScale, DisabledKeepsTheStreamsOwnNoise) {
  NoiseScaleConfig off;  // enabled false by default
  const ScaleTrack t = runScalarFilter(off, 9.0, 500, 3);
  EXPECT_DOUBLE_EQ(t.min, 1.0);
  EXPECT_DOUBLE_EQ(t.max, 1.0);
}

TEST(AdaptiveNoiseScale, AnEpochsRowsDoNotChangeTheScaleItWasFusedWith) {
  NoiseScaleEstimator est;
  est.configure(enabled(2, 1.0, 100.0));
  ScalarUpdateResult big;
  big.innovation = 10.0;  // a 10-sigma row
  big.innovation_var = 1.0;
  big.accepted = true;
  est.addRow(big);
  EXPECT_DOUBLE_EQ(est.scale(), 1.0);  // still the epoch's scale until it closes
  est.closeEpoch();
  EXPECT_DOUBLE_EQ(est.scale(), 1.0);  // the window (2 epochs) is not full yet
  est.addRow(big);
  est.closeEpoch();
  // q = 1 * (100 - 1 + 1) per row, two rows: the scale is 100, at the ceiling.
  EXPECT_DOUBLE_EQ(est.scale(), 100.0);
  EXPECT_EQ(est.counters().epochs, 2u);
  EXPECT_EQ(est.counters().epochs_scaled, 0u);  // both epochs were fused with 1
  ScalarUpdateResult gated = big;
  gated.accepted = false;  // an outlier the gate refused does not feed the estimate
  est.addRow(gated);
  est.closeEpoch();
  EXPECT_EQ(est.counters().epochs, 2u);
  EXPECT_EQ(est.counters().rows, 2u);
}

TEST(AdaptiveNoiseScale, RestartForgetsTheWindow) {
  NoiseScaleEstimator est;
  est.configure(enabled(1, 1.0, 50.0));
  ScalarUpdateResult r;
  r.innovation = 3.0;
  r.innovation_var = 1.0;
  r.accepted = true;
  est.addRow(r);
  est.closeEpoch();
  EXPECT_DOUBLE_EQ(est.scale(), 9.0);
  est.restart();
  EXPECT_DOUBLE_EQ(est.scale(), 1.0);
  EXPECT_EQ(est.counters().epochs, 1u);  // the counters run on
}
