// An error-state Kalman filter over the state layout (state_layout.hpp): the error estimate x, its
// covariance P and the set of active states. It knows nothing of the navigation state it corrects;
// the integrated filter (integrated_filter.hpp) owns the mechanization and applies the feedback.
#pragma once

#include <array>
#include <bitset>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "navbus/core/filter/aiding_measurements.hpp"
#include "navbus/core/ins/ins_error_model.hpp"
#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/math/kalman_update.hpp"

namespace navbus::core {

using StateVector = Eigen::Matrix<double, layout::kSize, 1>;

/// The navigation state an error estimate describes, corrected: errors are estimate minus
/// truth, so position, velocity and attitude (C_true = (I + [phi x]) C_est) lose them.
NavState correctedState(const NavState& s, const StateVector& error);

/// The mask with the given blocks active.
StateMask maskOf(std::initializer_list<StateBlock> blocks);

class ErrorState {
 public:
  void initialize(const StateMatrix& P0, const StateMask& active);

  /// x = Phi x, P = Phi P Phi^T + Q, Q = diag(q_diagonal) (the process noises of every
  /// configuration are uncorrelated), on the active states only: an inactive state keeps its
  /// variance, is not driven by the active ones and does not drive them (seed 004 fig. 9: each
  /// reduced filter uses its region of the 15-state system matrix). Phi's nonzero elements
  /// must lie within transitionPattern() (ins_error_model.hpp), as every transitionMatrix()
  /// does (asserted in builds without NDEBUG); that pattern is block upper triangular at
  /// layout::kCoupledSize, which the product exploits (sparse_rows.hpp).
  void predict(const StateMatrix& Phi, const StateVector& q_diagonal);

  /// Keeps, beside P, the part of it that the process noise of `states` added since the last
  /// forgetProcessNoise() (adaptive_process_noise.hpp): P_Q = Phi P_Q Phi^T + Q_states, carried
  /// through the updates as P is, without their R (carryThroughUpdate); a reset of P takes the
  /// reset rows out of it. An empty mask (the default) keeps nothing.
  void trackProcessNoise(const StateMask& states);
  bool tracksProcessNoise() const { return tracked_noise_.any(); }
  /// P_Q (zero when nothing is tracked).
  StateMatrix processNoisePart() const;
  /// Starts P_Q again from zero (the engine does it after each GNSS epoch it adapts from).
  void forgetProcessNoise();
  /// P_Q through an update that P took outside update(): row h with gain K.
  void carryProcessNoise(const Eigen::Matrix<double, 1, layout::kSize>& h, const StateVector& K);
  /// P_Q through the turn of one 3-state block (P's rows and columns turned by R, as the
  /// heading reset does).
  void turnProcessNoise(const StateBlock& block, const Eigen::Matrix3d& R);

  /// Sequential Joseph-form update, rows decorrelated by the Cholesky factor of R, inactive
  /// columns of H ignored. gate_sigma <= 0 disables gating. Returns one result per row.
  template <int M>
  std::array<ScalarUpdateResult, M> update(const AidingMeasurement<M>& m, double gate_sigma);

  /// Covariance reset rules of seed 004 (eq. 12): zero every off-diagonal element, then
  /// re-initialize the listed variances.
  void zeroOffDiagonal();
  void setVariances(const StateBlock& block, double sigma);
  /// Forgets what was known of state i: its error and correlations are zeroed, its variance
  /// set to sigma^2 (a re-initialisation from an independent measurement).
  void resetState(int i, double sigma);

  /// Changes the active set (inactive states keep their variance, cross terms removed).
  void setActive(const StateMask& active);
  /// Which active states updates correct; the other active ones are consider states
  /// (kalman_update.hpp): propagated and correlated, never corrected. Default: all.
  void setEstimated(const StateMask& estimated) { estimated_ = estimated; }

  /// The navigation state was corrected by dx: the error estimate becomes x - dx.
  void shift(const StateVector& dx) { x_ -= dx; }

  StateVector& x() { return x_; }
  const StateVector& x() const { return x_; }
  StateMatrix& P() { return P_; }
  const StateMatrix& P() const { return P_; }
  const StateMask& active() const { return active_; }
  const StateMask& estimated() const { return estimated_; }

 private:
  void removeInactiveCoupling();
  /// Takes state i's row and column out of P_Q (P's were replaced).
  void dropFromProcessNoise(int i);

  StateVector x_{StateVector::Zero()};
  StateMatrix P_{StateMatrix::Zero()};
  StateMask active_;
  /// transitionPattern() without the inactive states' coupling.
  SparsityPattern<layout::kSize> pattern_{transitionPattern()};
  StateMask estimated_{StateMask().set()};
  StateMask tracked_noise_;  ///< the states whose process noise P_Q holds
  /// P_Q (kSize x kSize while tracked, empty otherwise: a filter that does not track it, and
  /// each snapshot of one, carries no storage for it).
  Eigen::MatrixXd process_noise_;
  Eigen::Map<StateMatrix> processNoiseMap() {
    return Eigen::Map<StateMatrix>(process_noise_.data());
  }
};

template <int M>
std::array<ScalarUpdateResult, M> ErrorState::update(const AidingMeasurement<M>& m,
                                                     double gate_sigma) {
  using RowMatrix = Eigen::Matrix<double, M, layout::kSize>;
  // Whitened rows: L^-1 z and L^-1 H with R = L L^T (one row: divided by sqrt(r)).
  Eigen::Matrix<double, M, 1> z;
  RowMatrix H;
  if constexpr (M == 1) {
    const double l = std::sqrt(m.r(0, 0));
    z[0] = m.z[0] / l;
    H = m.h * (1.0 / l);  // as Eigen's triangular solve of a row: bit for bit
  } else {
    const Eigen::Matrix<double, M, M> L = m.r.llt().matrixL();
    z = L.template triangularView<Eigen::Lower>().solve(m.z);
    H = L.template triangularView<Eigen::Lower>().solve(m.h);
  }
  for (int j = 0; j < layout::kSize; ++j) {
    if (!active_[static_cast<std::size_t>(j)]) H.col(j).setZero();
  }
  std::array<ScalarUpdateResult, M> out;
  const bool carry = tracksProcessNoise();
  StateVector K = StateVector::Zero();
  for (int i = 0; i < M; ++i) {
    const auto k = static_cast<std::size_t>(i);
    out[k] = scalarUpdate<layout::kSize>(x_, P_, H.row(i), z[i], 1.0, gate_sigma, &estimated_,
                                         carry ? &K : nullptr);
    if (carry && out[k].accepted) carryProcessNoise(H.row(i), K);
  }
  return out;
}

}  // namespace navbus::core
