// Products with a sparse square matrix, such as the error-state transition matrix
// Phi = I + F dt + (F dt)^2 / 2 (about 110 of its 289 elements are nonzero): the covariance
// propagation Phi P Phi^T and the accumulated transition Phi Phi_acc cost a fraction of the
// dense fixed-size products, whose general blocked kernel dominated the offline run.
//
// The pattern is read from the matrix's values, or given: a structural pattern computed once
// (ins_error_model.hpp) saves reading it every cycle. Each output element is the sum of the
// products of pattern elements, in ascending index order; the terms left out are zero, so
// results agree with the dense product to rounding.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace navbus::core {

/// Which elements of an N x N matrix may be nonzero: the columns of each row.
template <int N>
class SparsityPattern {
 public:
  using Square = Eigen::Matrix<double, N, N>;

  /// The nonzero elements of A.
  static SparsityPattern of(const Square& A) {
    SparsityPattern p;
    for (int i = 0; i < N; ++i) {
      int n = 0;
      for (int k = 0; k < N; ++k) {
        p.cols_[idx(i)][idx(n)] = static_cast<std::uint8_t>(k);  // kept if nonzero (branch-free)
        n += A(i, k) != 0.0 ? 1 : 0;
      }
      p.count_[idx(i)] = n;
    }
    return p;
  }

  /// Whether every nonzero element of A is in the pattern.
  bool covers(const Square& A) const {
    Square mask = Square::Zero();
    for (int i = 0; i < N; ++i)
      for (int n = 0; n < count(i); ++n) mask(i, col(i, n)) = 1.0;
    return ((A.array() != 0.0) && (mask.array() == 0.0)).count() == 0;
  }

  int count(int row) const { return count_[idx(row)]; }
  int col(int row, int n) const { return cols_[idx(row)][idx(n)]; }
  int nonZeros() const {
    int n = 0;
    for (int c : count_) n += c;
    return n;
  }

 private:
  static std::size_t idx(int i) { return static_cast<std::size_t>(i); }
  std::array<std::array<std::uint8_t, N>, N> cols_{};
  std::array<int, N> count_{};
};

template <int N>
class SparseRows {
 public:
  using Square = Eigen::Matrix<double, N, N>;
  using Vector = Eigen::Matrix<double, N, 1>;
  using Pattern = SparsityPattern<N>;

  /// A with its nonzero elements (read from its values); A must outlive this object.
  explicit SparseRows(const Square& A) : a_(A), own_(Pattern::of(A)), p_(&own_) {}
  /// A with a known pattern that covers its nonzero elements (a structural one, computed
  /// once); A and the pattern must outlive this object.
  SparseRows(const Square& A, const Pattern& pattern) : a_(A), p_(&pattern) {}
  SparseRows(const SparseRows&) = delete;  // p_ may point into the object itself
  SparseRows& operator=(const SparseRows&) = delete;

  /// A x.
  Vector times(const Vector& x) const {
    Vector y;
    for (int i = 0; i < N; ++i) y[i] = rowDot(i, x.data());
    return y;
  }

  /// A B = (B^T A^T)^T, through contiguous column sums.
  Square times(const Square& B) const { return timesTransposed(B.transpose()).transpose(); }

  /// A B for a sparse B: only the products of nonzero elements.
  Square times(const SparseRows& B) const {
    Square out = Square::Zero();
    for (int i = 0; i < N; ++i) {
      for (int n = 0; n < p_->count(i); ++n) {
        const int k = p_->col(i, n);
        for (int m = 0; m < B.p_->count(k); ++m) {
          const int j = B.p_->col(k, m);
          out(i, j) += a_(i, k) * B.a_(k, j);
        }
      }
    }
    return out;
  }

  /// A P A^T for a symmetric P; the result is symmetric to the last bit (the upper triangle is
  /// computed, the lower one mirrored).
  Square sandwich(const Square& P) const {
    // T = P A^T: column i = sum_k A(i, k) P(:, k). A P A^T = A T = (T^T A^T)^T, and for a
    // symmetric result that is T^T A^T. Both steps are sums of contiguous columns (vectorized
    // axpys); the upper triangle is then mirrored, so the result is exactly symmetric.
    const Square Tt = timesTransposed(P).transpose();
    Square out = timesTransposed(Tt);
    for (int j = 0; j < N; ++j) {
      for (int i = 0; i < j; ++i) out(j, i) = out(i, j);
    }
    return out;
  }

  /// B A^T: column i = sum_k A(i, k) B(:, k).
  Square timesTransposed(const Square& B) const {
    Square out;
    for (int i = 0; i < N; ++i) {
      out.col(i).setZero();
      for (int n = 0; n < p_->count(i); ++n) {
        const int k = p_->col(i, n);
        out.col(i) += a_(i, k) * B.col(k);
      }
    }
    return out;
  }

  /// Elements of A in its pattern.
  int nonZeros() const { return p_->nonZeros(); }

 private:
  static std::size_t idx(int i) { return static_cast<std::size_t>(i); }

  double rowDot(int i, const double* v) const {
    double s = 0.0;
    for (int n = 0; n < p_->count(i); ++n) {
      const int k = p_->col(i, n);
      s += a_(i, k) * v[k];
    }
    return s;
  }

  const Square& a_;
  Pattern own_;
  const Pattern* p_;
};

}  // namespace navbus::core
