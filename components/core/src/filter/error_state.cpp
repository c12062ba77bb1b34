#include "navbus/core/filter/error_state.hpp"

#include <cassert>

#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/sparse_rows.hpp"

namespace navbus::core {

NavState correctedState(const NavState& s, const StateVector& error) {
  NavState out = s;
  out.position = earth::offsetNed(s.position, -error.segment<3>(layout::kPos.index));
  out.vel_ned_mps -= error.segment<3>(layout::kVel.index);
  out.q_b_to_n = (quaternionFromRotationVector(error.segment<3>(layout::kAtt.index)) * s.q_b_to_n)
                     .normalized();
  return out;
}

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
  forgetProcessNoise();
  active_ = active;
  estimated_.set();
  removeInactiveCoupling();
}

void ErrorState::predict(const StateMatrix& Phi, const StateVector& q_diagonal) {
  // Phi is sparse, within the error model's transition pattern (sparse_rows.hpp,
  // ins_error_model.hpp), and block upper triangular: no navigation error drives the biases or
  // the clock. The pattern used here leaves the inactive states out of the coupling, so
  // whatever Phi holds for them, they neither drive the active states nor are driven.
  assert(transitionPattern().covers(Phi));
  const SparseRows<layout::kSize> phi(Phi, pattern_);
  const StateVector variance_before = P_.diagonal();
  x_ = phi.times(x_);
  P_ = phi.sandwichBlockTriangular<layout::kCoupledSize>(P_);
  if (tracksProcessNoise()) {
    Eigen::Map<StateMatrix> pq = processNoiseMap();
    pq = phi.sandwichBlockTriangular<layout::kCoupledSize>(StateMatrix(pq));
    for (int i = 0; i < layout::kSize; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (active_[k] && tracked_noise_[k]) pq(i, i) += q_diagonal[i];
    }
  }
  for (int i = 0; i < layout::kSize; ++i) {
    if (active_[static_cast<std::size_t>(i)]) {
      P_(i, i) += q_diagonal[i];
    } else {
      P_(i, i) = variance_before[i];  // kept as it was, whatever Phi(i, i) is
      x_[i] = 0.0;
    }
  }
}

void ErrorState::trackProcessNoise(const StateMask& states) {
  tracked_noise_ = states;
  if (tracksProcessNoise())
    process_noise_.setZero(layout::kSize, layout::kSize);
  else
    process_noise_.resize(0, 0);
}

StateMatrix ErrorState::processNoisePart() const {
  if (!tracksProcessNoise()) return StateMatrix::Zero();
  return Eigen::Map<const StateMatrix>(process_noise_.data());
}

void ErrorState::forgetProcessNoise() {
  if (tracksProcessNoise()) process_noise_.setZero();
}

void ErrorState::carryProcessNoise(const Eigen::Matrix<double, 1, layout::kSize>& h,
                                   const StateVector& K) {
  if (!tracksProcessNoise()) return;
  Eigen::Map<StateMatrix> pq = processNoiseMap();
  carryThroughUpdate<layout::kSize>(pq, h, K);
}

void ErrorState::turnProcessNoise(const StateBlock& block, const Eigen::Matrix3d& R) {
  if (!tracksProcessNoise()) return;
  Eigen::Map<StateMatrix> pq = processNoiseMap();
  pq.middleRows<3>(block.index) = (R * pq.middleRows<3>(block.index)).eval();
  pq.middleCols<3>(block.index) = (pq.middleCols<3>(block.index) * R.transpose()).eval();
}

void ErrorState::dropFromProcessNoise(int i) {
  if (!tracksProcessNoise()) return;
  process_noise_.row(i).setZero();
  process_noise_.col(i).setZero();
}

void ErrorState::zeroOffDiagonal() {
  P_ = StateMatrix(P_.diagonal().asDiagonal());
  // P - P_Q was a covariance: its diagonal, and so diag(P) - diag(P_Q), is not negative.
  if (tracksProcessNoise()) {
    const Eigen::VectorXd d = process_noise_.diagonal();
    process_noise_ = d.asDiagonal();
  }
}

void ErrorState::setVariances(const StateBlock& block, double sigma) {
  for (int i = block.index; i < block.end(); ++i) {
    P_(i, i) = sigma * sigma;
    dropFromProcessNoise(i);
  }
}

void ErrorState::resetState(int i, double sigma) {
  P_.row(i).setZero();
  P_.col(i).setZero();
  P_(i, i) = sigma * sigma;
  x_[i] = 0.0;
  dropFromProcessNoise(i);
}

void ErrorState::setActive(const StateMask& active) {
  active_ = active;
  removeInactiveCoupling();
}

void ErrorState::removeInactiveCoupling() {
  pattern_ = transitionPattern();
  for (int i = 0; i < layout::kSize; ++i) {
    if (active_[static_cast<std::size_t>(i)]) continue;
    const double v = P_(i, i);
    P_.row(i).setZero();
    P_.col(i).setZero();
    P_(i, i) = v;
    x_[i] = 0.0;
    dropFromProcessNoise(i);
    pattern_.decouple(i);
  }
}

}  // namespace navbus::core
