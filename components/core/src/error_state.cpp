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

void ErrorState::initialize(const Matrix17& P0, const StateMask& active) {
  x_.setZero();
  P_ = P0;
  active_ = active;
  removeInactiveCoupling();
}

void ErrorState::predict(const Matrix17& Phi_full, const Vector17& q_diagonal) {
  Vector17 q = q_diagonal;
  const bool all_active = active_.all();
  Matrix17 Phi_reduced;
  if (!all_active) {
    Phi_reduced = Phi_full;
    for (int i = 0; i < tc17::kSize; ++i) {
      if (active_[static_cast<std::size_t>(i)]) continue;
      Phi_reduced.row(i).setZero();
      Phi_reduced.col(i).setZero();
      Phi_reduced(i, i) = 1.0;
      q[i] = 0.0;
    }
  }
  // Phi is sparse, within the error model's transition pattern (sparse_rows.hpp,
  // ins_error_model.hpp); the product is symmetric by construction.
  const Matrix17& Phi = all_active ? Phi_full : Phi_reduced;
  assert(transitionPattern().covers(Phi));
  const SparseRows<tc17::kSize> phi(Phi, transitionPattern());
  x_ = phi.times(x_);
  P_ = phi.sandwich(P_);
  P_.diagonal() += q;
}

void ErrorState::zeroOffDiagonal() {
  P_ = Matrix17(P_.diagonal().asDiagonal());
}

void ErrorState::setVariances(const StateBlock& block, double sigma) {
  for (int i = block.index; i < block.end(); ++i) P_(i, i) = sigma * sigma;
}

void ErrorState::setActive(const StateMask& active) {
  active_ = active;
  removeInactiveCoupling();
}

void ErrorState::removeInactiveCoupling() {
  for (int i = 0; i < tc17::kSize; ++i) {
    if (active_[static_cast<std::size_t>(i)]) continue;
    const double v = P_(i, i);
    P_.row(i).setZero();
    P_.col(i).setZero();
    P_(i, i) = v;
    x_[i] = 0.0;
  }
}

}  // namespace navbus::core
