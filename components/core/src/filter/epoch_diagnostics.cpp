#include "navbus/core/filter/epoch_diagnostics.hpp"

#include <array>

namespace navbus::core {

void AppliedGain::prepare(EpochDiagnostics& d, const StateMatrix& prior_P) {
  const Eigen::Index m = d.h.rows();
  std::array<int, layout::kSize> support{};
  int n_support = 0;
  for (int k = 0; k < layout::kSize; ++k) {
    if (!d.h.col(k).isZero(0.0)) support[static_cast<std::size_t>(n_support++)] = k;
  }
  n_reached_ = 0;
  for (int j = 0; j < layout::kSize; ++j) {
    for (int a = 0; a < n_support; ++a) {
      if (prior_P(support[static_cast<std::size_t>(a)], j) != 0.0) {
        reached_[static_cast<std::size_t>(n_reached_++)] = j;
        break;
      }
    }
  }
  // Each row's own support (a pseudorange row: position and its receiver's clock, 4 to 8 of
  // H's 8 to 11 columns): H P- and V over it.
  row_support_.resize(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    RowSupport& rs = row_support_[static_cast<std::size_t>(i)];
    rs.count = 0;
    for (int a = 0; a < n_support; ++a) {
      const int k = support[static_cast<std::size_t>(a)];
      if (d.h(i, k) != 0.0) rs.column[static_cast<std::size_t>(rs.count++)] = k;
    }
  }
  hp_.setZero(m, layout::kSize);
  for (int b = 0; b < n_reached_; ++b) {
    const int j = reached_[static_cast<std::size_t>(b)];
    for (Eigen::Index i = 0; i < m; ++i) {
      const RowSupport& rs = row_support_[static_cast<std::size_t>(i)];
      double sum = 0.0;
      for (int a = 0; a < rs.count; ++a) {
        const int k = rs.column[static_cast<std::size_t>(a)];
        sum += d.h(i, k) * prior_P(k, j);
      }
      hp_(i, j) = sum;
    }
  }
  // V = (H P-) H^T, symmetric: the lower triangle, mirrored.
  d.innovation_cov.resize(m, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const RowSupport& rs = row_support_[static_cast<std::size_t>(i)];
    for (Eigen::Index j = i; j < m; ++j) {
      double v = 0.0;
      for (int a = 0; a < rs.count; ++a) {
        const int k = rs.column[static_cast<std::size_t>(a)];
        v += hp_(j, k) * d.h(i, k);
      }
      d.innovation_cov(j, i) = v;
      d.innovation_cov(i, j) = v;
    }
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
  // K^T = V^-1 H P- on the reached columns; the gain's other rows are zero.
  rhs_.resize(m, layout::kSize);
  auto rhs = rhs_.leftCols(n_reached_);
  for (int b = 0; b < n_reached_; ++b) rhs.col(b) = hp_.col(reached_[static_cast<std::size_t>(b)]);
  llt_.solveInPlace(rhs);
  d.k.setZero(layout::kSize, m);
  for (int b = 0; b < n_reached_; ++b)
    d.k.row(reached_[static_cast<std::size_t>(b)]) = rhs.col(b).transpose();
  for (Eigen::Index i = 0; i < m; ++i) {
    if (!d.used[static_cast<std::size_t>(i)]) d.k.col(i).setZero();
  }
}

bool AppliedGain::computeFromPosterior(EpochDiagnostics& d, const StateMatrix& posterior_P,
                                       const Eigen::VectorXd& r, const StateMask& estimated) const {
  const Eigen::Index m = d.h.rows();
  for (int b = 0; b < n_reached_; ++b) {
    if (!estimated[static_cast<std::size_t>(reached_[static_cast<std::size_t>(b)])]) return false;
  }
  for (Eigen::Index i = 0; i < m; ++i) {
    if (d.used[static_cast<std::size_t>(i)] && !(r[i] > 0.0)) return false;
  }
  // Column i of K is P+ h_i^T / r_i over h_i's nonzero elements (prepare()'s row supports), on
  // the reached states: P+ is zero (as P-) between them and the others, whose gain rows stay 0.
  d.k.setZero(layout::kSize, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    if (!d.used[static_cast<std::size_t>(i)]) continue;
    const RowSupport& rs = row_support_[static_cast<std::size_t>(i)];
    std::array<double, layout::kSize> h_over_r{};
    for (int a = 0; a < rs.count; ++a)
      h_over_r[static_cast<std::size_t>(a)] = d.h(i, rs.column[static_cast<std::size_t>(a)]) / r[i];
    for (int b = 0; b < n_reached_; ++b) {
      const int j = reached_[static_cast<std::size_t>(b)];
      double sum = 0.0;
      for (int a = 0; a < rs.count; ++a)
        sum += posterior_P(j, rs.column[static_cast<std::size_t>(a)]) *
               h_over_r[static_cast<std::size_t>(a)];
      d.k(j, i) = sum;
    }
  }
  return true;
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
