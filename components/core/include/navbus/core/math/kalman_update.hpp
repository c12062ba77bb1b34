// Kalman measurement update in Joseph form, one scalar measurement at a time, with innovation
// gating. The test ratio eps^2 / (gate^2 V) is returned for publication (PX4-style: fault state
// is data); a measurement with ratio > 1 is rejected and leaves the state untouched.
#pragma once

#include <array>
#include <bitset>
#include <cmath>

#include <Eigen/Core>

namespace navbus::core {

struct ScalarUpdateResult {
  double innovation{0.0};      ///< eps = z - H x (measured minus predicted, in error-state form)
  double innovation_var{0.0};  ///< V = H P H^T + R
  double test_ratio{0.0};      ///< eps^2 / (gate^2 V)
  bool accepted{false};
};

/// Updates the error state x and covariance P with the scalar measurement z = h x + v,
/// var(v) = r. `gate_sigma` is the gate in standard deviations (e.g. 5); <= 0 disables it.
/// Joseph form P = (I - K h) P (I - K h)^T + K r K^T (expanded, see below) keeps P symmetric
/// positive definite even with rounding; the result is symmetrized. States outside
/// `estimated` (when given) are consider states (Schmidt-Kalman): their gain is zero, so they
/// are not corrected, but their covariance and correlations are updated and keep counting in
/// the gains of the others. `gain` (when given) receives the K applied (unchanged when the row
/// is not accepted).
template <int N>
ScalarUpdateResult scalarUpdate(Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, N, N>& P,
                                const Eigen::Matrix<double, 1, N>& h, double z, double r,
                                double gate_sigma, const std::bitset<N>* estimated = nullptr,
                                Eigen::Matrix<double, N, 1>* gain = nullptr) {
  ScalarUpdateResult out;
  // An aiding row reaches a few states (3 to 11 of the layout's 38): P h^T and h x over h's
  // nonzero elements only.
  std::array<int, N> support{};
  int n_support = 0;
  for (int k = 0; k < N; ++k) {
    if (h[k] != 0.0) support[static_cast<std::size_t>(n_support++)] = k;
  }
  Eigen::Matrix<double, N, 1> Ph = Eigen::Matrix<double, N, 1>::Zero();
  double hx = 0.0;
  for (int n = 0; n < n_support; ++n) {
    const int k = support[static_cast<std::size_t>(n)];
    Ph.noalias() += P.col(k) * h[k];
    hx += h[k] * x[k];
  }
  double hPh = 0.0;
  for (int n = 0; n < n_support; ++n) {
    const int k = support[static_cast<std::size_t>(n)];
    hPh += h[k] * Ph[k];
  }
  out.innovation = z - hx;
  out.innovation_var = hPh + r;
  // Without a gate (gate_sigma <= 0) the ratio is the normalized innovation squared eps^2 / V.
  const double gate2 = gate_sigma > 0.0 ? gate_sigma * gate_sigma : 1.0;
  out.test_ratio = out.innovation * out.innovation / (gate2 * out.innovation_var);
  if (!(out.innovation_var > 0.0) || !std::isfinite(out.test_ratio)) return out;
  if (gate_sigma > 0.0 && !(out.test_ratio <= 1.0)) return out;
  const double V = out.innovation_var;
  Eigen::Matrix<double, N, 1> K = Ph * (1.0 / V);  // one division, not N
  if (estimated != nullptr) {
    for (int i = 0; i < N; ++i) {
      if (!(*estimated)[static_cast<std::size_t>(i)]) K[i] = 0.0;
    }
  }
  x += K * out.innovation;
  // Joseph form expanded for one row, O(N^2) instead of two N^3 products: with Ph = P h^T and
  // h P h^T + r = V, (I - K h) P (I - K h)^T + K r K^T = P - K Ph^T - Ph K^T + V K K^T, an
  // identity for any gain K (so it keeps the Joseph form's tolerance of gain errors; Bierman,
  // Factorization Methods for Discrete Sequential Estimation, 1977, ch. V). The change is zero
  // in every row and column where Ph is (K is Ph / V or 0 there): states the row does not
  // reach through P, such as inactive ones. It is symmetric: computed once per pair and written
  // to both halves.
  std::array<int, N> reached{};
  int n_reached = 0;
  for (int i = 0; i < N; ++i) {
    if (Ph[i] != 0.0) reached[static_cast<std::size_t>(n_reached++)] = i;
  }
  for (int b = 0; b < n_reached; ++b) {
    const int j = reached[static_cast<std::size_t>(b)];
    const double kj = K[j], phj = Ph[j], vkj = V * kj;
    for (int a = 0; a <= b; ++a) {
      const int i = reached[static_cast<std::size_t>(a)];
      const double p = P(i, j) - K[i] * phj - Ph[i] * kj + K[i] * vkj;
      P(i, j) = p;
      P(j, i) = p;
    }
  }
  if (gain != nullptr) *gain = K;
  out.accepted = true;
  return out;
}

/// A part S of the covariance (the share of one noise source) through an update of row h with
/// gain K: the Joseph form without the measurement's own K r K^T, S = (I - K h) S (I - K h)^T,
/// expanded as in scalarUpdate. P is linear in its sources for given gains, so each source's
/// share can be carried on its own.
/// S: an N x N matrix or a map of one.
template <int N, typename Square>
void carryThroughUpdate(Eigen::MatrixBase<Square>& S, const Eigen::Matrix<double, 1, N>& h,
                        const Eigen::Matrix<double, N, 1>& K) {
  const Eigen::Matrix<double, N, 1> Sh = S * h.transpose();
  const double hSh = h.dot(Sh.transpose());
  S.noalias() -= K * Sh.transpose();
  S.noalias() -= Sh * K.transpose();
  S.noalias() += (hSh * K) * K.transpose();
  S = (0.5 * (S + S.transpose())).eval();
}

}  // namespace navbus::core
