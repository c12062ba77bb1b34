// Products with a sparse square matrix, such as the error-state transition matrix
// Phi = I + F dt + (F dt)^2 / 2 (about 110 of its 289 elements are nonzero): the covariance
// propagation Phi P Phi^T and the accumulated transition Phi Phi_acc cost a fraction of the
// dense fixed-size products, whose general blocked kernel dominated the offline run.
//
// The pattern is read from the matrix's values, so an element that happens to be zero (a state
// switched off, a zero specific force component) is skipped too. Each output element is the sum
// of the same nonzero products as the dense product, in ascending index order; zero terms are
// left out, so results agree with the dense product to rounding.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace navbus::core {

template <int N>
class SparseRows {
 public:
  using Square = Eigen::Matrix<double, N, N>;
  using Vector = Eigen::Matrix<double, N, 1>;

  /// Records the nonzero columns of each row of A; A must outlive this object.
  explicit SparseRows(const Square& A) : a_(A) {
    for (int i = 0; i < N; ++i) {
      int n = 0;
      for (int k = 0; k < N; ++k) {
        cols_[idx(i)][idx(n)] = static_cast<std::uint8_t>(k);  // kept if nonzero (branch-free)
        n += A(i, k) != 0.0 ? 1 : 0;
      }
      count_[idx(i)] = n;
    }
  }

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
      for (int n = 0; n < count_[idx(i)]; ++n) {
        const int k = cols_[idx(i)][idx(n)];
        for (int m = 0; m < B.count_[idx(k)]; ++m) {
          const int j = B.cols_[idx(k)][idx(m)];
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
      for (int n = 0; n < count_[idx(i)]; ++n) {
        const int k = cols_[idx(i)][idx(n)];
        out.col(i) += a_(i, k) * B.col(k);
      }
    }
    return out;
  }

  /// Nonzero elements of A.
  int nonZeros() const {
    int n = 0;
    for (int c : count_) n += c;
    return n;
  }

 private:
  static std::size_t idx(int i) { return static_cast<std::size_t>(i); }

  double rowDot(int i, const double* v) const {
    double s = 0.0;
    for (int n = 0; n < count_[idx(i)]; ++n) {
      const int k = cols_[idx(i)][idx(n)];
      s += a_(i, k) * v[k];
    }
    return s;
  }

  const Square& a_;
  std::array<std::array<std::uint8_t, N>, N> cols_{};
  std::array<int, N> count_{};
};

}  // namespace navbus::core
