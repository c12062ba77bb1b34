#include "navbus/core/error_state.hpp"

#include <cassert>

#include "navbus/core/sparse_rows.hpp"

namespace navbus::core {

StateMask maskOf(std::initializer_list<StateBlock> blocks) {
  StateMask m;
  for (const StateBlock& b : blocks) {
    for (int i = b.index; i < b.end(); ++i) m.set(static_cast<std::size_t>(i));
  }
  return m;
}

void ErrorState::initialize(const StateMatrix& P0, const StateMask& active) {
  x_.setZero();
  P_ = P0;
  active_ = active;
  estimated_.set();
  removeInactiveCoupling();
}

namespace {
/// Whether Phi leaves state i alone: row i and column i are those of the identity.
bool leavesAlone(const StateMatrix& Phi, int i) {
  for (int k = 0; k < layout::kSize; ++k) {
    const double unit = k == i ? 1.0 : 0.0;
    if (Phi(i, k) != unit || Phi(k, i) != unit) return false;
  }
  return true;
}
}  // namespace

void ErrorState::predict(const StateMatrix& Phi_full, const StateVector& q_diagonal) {
  StateVector q = q_diagonal;
  // Inactive states are cut out of Phi; those it already leaves alone (a block no sensor of
  // the configuration drives, such as the star-tracker bias of a GNSS/INS filter) need no copy.
  bool reduce = false;
  for (int i = 0; i < layout::kSize; ++i) {
    if (active_[static_cast<std::size_t>(i)]) continue;
    q[i] = 0.0;
    reduce = reduce || !leavesAlone(Phi_full, i);
  }
  StateMatrix Phi_reduced;
  if (reduce) {
    Phi_reduced = Phi_full;
    for (int i = 0; i < layout::kSize; ++i) {
      if (active_[static_cast<std::size_t>(i)]) continue;
      Phi_reduced.row(i).setZero();
      Phi_reduced.col(i).setZero();
      Phi_reduced(i, i) = 1.0;
    }
  }
  // Phi is sparse, within the error model's transition pattern (sparse_rows.hpp,
  // ins_error_model.hpp); the product is symmetric by construction.
  const StateMatrix& Phi = reduce ? Phi_reduced : Phi_full;
  assert(transitionPattern().covers(Phi));
  const SparseRows<layout::kSize> phi(Phi, transitionPattern());
  x_ = phi.times(x_);
  P_ = phi.sandwich(P_);
  P_.diagonal() += q;
}

void ErrorState::zeroOffDiagonal() {
  P_ = StateMatrix(P_.diagonal().asDiagonal());
}

void ErrorState::setVariances(const StateBlock& block, double sigma) {
  for (int i = block.index; i < block.end(); ++i) P_(i, i) = sigma * sigma;
}

void ErrorState::setActive(const StateMask& active) {
  active_ = active;
  removeInactiveCoupling();
}

void ErrorState::removeInactiveCoupling() {
  for (int i = 0; i < layout::kSize; ++i) {
    if (active_[static_cast<std::size_t>(i)]) continue;
    const double v = P_(i, i);
    P_.row(i).setZero();
    P_.col(i).setZero();
    P_(i, i) = v;
    x_[i] = 0.0;
  }
}

}  // namespace navbus::core
