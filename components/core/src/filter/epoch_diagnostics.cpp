#include "navbus/core/filter/epoch_diagnostics.hpp"

#include <array>

namespace navbus::core {

void AppliedGain::prepare(EpochDiagnostics& d, const StateMatrix& prior_P) {
  const Eigen::Index m = d.h.rows();
  std::array<Eigen::Index, layout::kSize> support{};
  std::size_t n = 0;
  for (Eigen::Index k = 0; k < layout::kSize; ++k) {
    if (!d.h.col(k).isZero(0.0)) support[n++] = k;
  }
  hp_.setZero(m, layout::kSize);
  for (std::size_t a = 0; a < n; ++a) {
    const Eigen::Index k = support[a];
    hp_.noalias() += d.h.col(k) * prior_P.row(k);
  }
  d.innovation_cov.setZero(m, m);
  for (std::size_t a = 0; a < n; ++a) {
    const Eigen::Index k = support[a];
    d.innovation_cov.noalias() += hp_.col(k) * d.h.col(k).transpose();
  }
}

void AppliedGain::compute(EpochDiagnostics& d) {
  const Eigen::Index m = d.h.rows();
  cov_ = d.innovation_cov;
  for (Eigen::Index i = 0; i < m; ++i) {
    if (d.used[static_cast<std::size_t>(i)]) continue;
    cov_.row(i).setZero();
    cov_.col(i).setZero();
    cov_(i, i) = 1.0;
  }
  llt_.compute(cov_);
  d.k = llt_.solve(hp_).transpose();
  for (Eigen::Index i = 0; i < m; ++i) {
    if (!d.used[static_cast<std::size_t>(i)]) d.k.col(i).setZero();
  }
}

void fixEpochDiagnostics(const FixEpochInput& in, AppliedGain& gain, EpochDiagnostics& d) {
  constexpr int kRows = 6;
  d.sv_ids.clear();
  d.is_rate.clear();
  d.used.assign(in.used.begin(), in.used.end());
  d.test_ratio.assign(in.test_ratio.begin(), in.test_ratio.end());
  d.innovation.resize(kRows);
  d.h.resize(kRows, layout::kSize);
  Eigen::Matrix<double, kRows, kRows> r = Eigen::Matrix<double, kRows, kRows>::Zero();
  for (int block = 0; block < 2; ++block) {
    const VectorMeasurement& m = block == 0 ? *in.position : *in.velocity;
    d.innovation.segment<3>(3 * block) = m.z;
    d.h.middleRows<3>(3 * block) = m.h;
    r.block<3, 3>(3 * block, 3 * block) = m.r;
    for (int axis = 0; axis < 3; ++axis) {
      d.sv_ids.push_back(kFixAxisSources[static_cast<std::size_t>(axis)]);
      d.is_rate.push_back(block == 1);
    }
  }
  for (int j = 0; j < layout::kSize; ++j) {
    if (!in.active[static_cast<std::size_t>(j)]) d.h.col(j).setZero();
  }
  gain.prepare(d, *in.prior_P);
  d.innovation_cov += r;
  d.phi = *in.phi;
  gain.compute(d);
  for (int j = 0; j < layout::kSize; ++j) {
    if (!in.estimated[static_cast<std::size_t>(j)]) d.k.row(j).setZero();
  }
}

}  // namespace navbus::core
