// Adaptive measurement noise, bounded and visible: one scale per aiding stream on the
// stream's own R, estimated from its innovations by covariance matching over a sliding window
// (Mehra 1972; Mohamed & Schwarz 1999, "Adaptive Kalman filtering for INS/GPS", eq. 20 for R).
//
// For one fused row with the stream's nominal variance r0, fused with r = s r0, the update
// reports the whitened innovation nu_w = nu / sqrt(r) and its variance V_w = a / r + 1, where
// a = H P- H^T is the prediction's part. A consistent model has E[nu^2] = a + s_true r0, so
//   q = (nu^2 - a) / r0 = s (nu_w^2 - V_w + 1)                       (one row's estimate)
// is unbiased for the true scale, and over the rows of the last N epochs
//   s^ = sum q / rows,   s = min(max(s^, floor), ceiling).
// The scale of an epoch comes from the epochs before it (its own innovations never explain
// themselves away), and until the window holds N epochs the scale is 1 (the stream's own R),
// bounded the same way. The ceiling is what keeps a fault visible: a stream can be trusted at
// most sqrt(ceiling) times less than it says, so a fault larger than that still fails the
// consistency monitor, the gate and the GLR.
//
// Covariance matching rather than a variational Bayes filter: it needs no prior on R, its
// estimate is a plain mean an integrator can check from the published innovations, and the
// window sets how fast it follows (a variational filter's forgetting factor does the same, less
// visibly). Only accepted rows count: a gated row is an outlier the filter did not absorb.
// Pure math, fixed storage.
#pragma once

#include <array>
#include <cstdint>

#include "navbus/core/math/kalman_update.hpp"

namespace navbus::core {

struct NoiseScaleConfig {
  bool enabled{false};    ///< false: every stream keeps its own R (scale 1)
  int window_epochs{20};  ///< N: epochs per estimate (1..NoiseScaleEstimator::kMaxWindow)
  double floor{1.0};      ///< smallest scale on R (1: never trust a stream more than it says)
  double ceiling{9.0};    ///< largest scale on R (9: sigmas at most 3 times the stream's own)
};

struct NoiseScaleCounters {
  std::uint64_t epochs{0};             ///< epochs that fed the estimate
  std::uint64_t rows{0};               ///< accepted rows that fed it
  std::uint64_t epochs_scaled{0};      ///< epochs fused with a scale other than 1
  std::uint64_t epochs_at_ceiling{0};  ///< ... with the scale at the ceiling
  double max_scale{1.0};               ///< largest scale applied
};

class NoiseScaleEstimator {
 public:
  static constexpr int kMaxWindow = 128;

  void configure(const NoiseScaleConfig& config);
  /// The scale on the stream's R for the next epoch (1 when disabled).
  double scale() const { return scale_; }
  /// One row of the epoch fused with scale() (whitened result of ErrorState::update).
  void addRow(const ScalarUpdateResult& row);
  /// Closes the epoch: the rows added since the last close join the window, the scale for the
  /// next epoch is estimated, and the epoch is counted with the scale it was fused with.
  void closeEpoch();
  /// Forgets the window (the filter restarted): scale 1 until it is full again.
  void restart();
  const NoiseScaleCounters& counters() const { return counters_; }

 private:
  struct Epoch {
    double q_sum{0.0};
    int rows{0};
  };
  double bounded(double s) const;

  NoiseScaleConfig config_;
  std::array<Epoch, kMaxWindow> window_{};
  Epoch open_;
  int count_{0}, next_{0};
  double scale_{1.0};
  NoiseScaleCounters counters_;
};

}  // namespace navbus::core
