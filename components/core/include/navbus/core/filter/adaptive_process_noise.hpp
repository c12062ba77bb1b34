// Adaptive process noise, bounded and visible: one scale alpha on the inertial process noise Q
// (the velocity and attitude white noises and the IMU bias random walks), estimated from the
// GNSS innovations by covariance matching with a fading memory (the innovation-based Q
// estimation of Mohamed & Schwarz 1999, "Adaptive Kalman filtering for INS/GPS", reduced to one
// scale as the measurement scale beside it is, adaptive_noise_scale.hpp).
//
// For the gains the filter applied, its covariance is linear in its noise sources, so the prior
// covariance of a GNSS epoch splits into the share of the inertial process noise added since the
// previous GNSS epoch, carried through the propagation and the updates between (ZUPT, NHC:
// ErrorState::processNoisePart, carryThroughUpdate), and the rest:
//   P- = P_rest + P_Q,   P_Q = sum over the steps of (what followed) (alpha Q0_j) (...)^T.
// For one row with prior variance a = h P- h^T, process part p = h P_Q h^T and the variance r
// it was fused with, a consistent model has
//   E[nu^2] = (a - p) + alpha_true g + r,   g = p / alpha (the nominal process part),
// so y = nu^2 - (V - p), V = a + r, is alpha_true g plus a noise of variance about 2 V^2. The
// weighted least-squares estimate over the rows seen, older rows fading with the memory tau,
// and n0 rows' worth of the configured Q as a prior (rows all process noise at the scale in
// use, alpha, so that the prior weighs as much beside a large scale as beside 1),
//   alpha^ = (sum w g y / V^2 + n0 / alpha^2) / (sum w g^2 / V^2 + n0 / alpha^2),
//   w = exp(-(t_now - t_row) / tau),   alpha = min(max(alpha^, floor), ceiling),
// leans on the rows where the process noise dominates their variance (after an outage, a long
// interval between fixes) and hardly on the others (where R does). The scale of an epoch comes
// from the epochs before it. Only accepted rows count. The measurement's own scale (on R) is
// taken as given: each scale is estimated given the other's current value, and the two separate
// because their rows' weights differ (R dominates a fix 0.25 s after the previous one, Q one
// after a 15 s outage).
// Covariance matching with a fading memory rather than a window: the rows that carry the
// information (the first fix after an outage) come tens of seconds apart, and a window of
// epochs would forget one before the next comes. Pure math, fixed storage.
#pragma once

#include <cstdint>

namespace navbus::core {

struct ProcessNoiseScaleConfig {
  bool enabled{false};     ///< false: the configured Q (scale 1)
  double memory_s{600.0};  ///< tau: a row's weight falls by e in this time [s]
  double prior_rows{1.0};  ///< n0: weight of the configured Q in rows whose variance is all Q
  double floor{1.0};       ///< smallest scale on Q (1: never less noise than configured)
  double ceiling{9.0};     ///< largest scale on Q (9: the random walks' sigmas at most 3x)
};

struct ProcessNoiseScaleCounters {
  std::uint64_t epochs{0};             ///< epochs that fed the estimate
  std::uint64_t rows{0};               ///< accepted rows with a process part
  std::uint64_t epochs_scaled{0};      ///< epochs propagated into with a scale other than 1
  std::uint64_t epochs_at_ceiling{0};  ///< ... with the scale at the ceiling
  double max_scale{1.0};               ///< largest scale applied
};

/// One accepted row of an epoch, from the prior: nu, V = h P- h^T + r, p = h P_Q h^T.
struct ProcessNoiseRow {
  double innovation{0.0};
  double innovation_var{0.0};
  double process_var{0.0};
};

class ProcessNoiseScaleEstimator {
 public:
  void configure(const ProcessNoiseScaleConfig& config);
  /// The scale on Q for the propagation from now on (1 when disabled).
  double scale() const { return scale_; }
  /// One row of the epoch being fused (its process part propagated with scale()).
  void addRow(const ProcessNoiseRow& row);
  /// Closes the epoch at time_ns: its rows join the faded sums, the scale is re-estimated.
  void closeEpoch(std::int64_t time_ns);
  /// Forgets the rows (the filter restarted): the configured Q until rows come again.
  void restart();
  /// The rows' weight in the sums now, sum w (p / V)^2: in rows whose variance is all process
  /// noise at the scale they were fused with.
  double informationRows() const { return info_; }
  const ProcessNoiseScaleCounters& counters() const { return counters_; }

 private:
  double bounded(double s) const;

  ProcessNoiseScaleConfig config_;
  double num_{0.0}, den_{0.0}, info_{0.0};                 ///< faded sums over the rows closed
  double open_num_{0.0}, open_den_{0.0}, open_info_{0.0};  ///< the epoch being fused
  int open_rows_{0};
  std::int64_t last_close_ns_{0};
  bool closed_any_{false};
  double scale_{1.0};
  ProcessNoiseScaleCounters counters_;
};

}  // namespace navbus::core
