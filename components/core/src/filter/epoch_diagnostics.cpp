#include "navbus/core/filter/epoch_diagnostics.hpp"

namespace navbus::core {

void AppliedGain::compute(EpochDiagnostics& d, const StateMatrix& prior_P) {
  const Eigen::Index m = d.h.rows();
  cov_ = d.innovation_cov;
  for (Eigen::Index i = 0; i < m; ++i) {
    if (d.used[static_cast<std::size_t>(i)]) continue;
    cov_.row(i).setZero();
    cov_.col(i).setZero();
    cov_(i, i) = 1.0;
  }
  llt_.compute(cov_);
  d.k = llt_.solve(d.h * prior_P).transpose();
  for (Eigen::Index i = 0; i < m; ++i) {
    if (!d.used[static_cast<std::size_t>(i)]) d.k.col(i).setZero();
  }
}

}  // namespace navbus::core
