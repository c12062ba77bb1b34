// Products with a sparse square matrix, such as the error-state transition matrix
// Phi = I + F dt + (F dt)^2 / 2 (about 130 of its 400 elements are nonzero): the covariance
// propagation Phi P Phi^T and the accumulated transition Phi Phi_acc cost a fraction of the
// dense fixed-size products, whose general blocked kernel dominated the offline run.
//
// The pattern is read from the matrix's values, or given: a structural pattern computed once
// (ins_error_model.hpp) saves reading it every cycle. Each output element is the sum of the
// products of pattern elements, in ascending index order; the terms left out are zero, so
// results agree with the dense product to rounding.
#pragma once

#include <array>
#include <cassert>
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

  /// Removes every element of row i and column i except the diagonal one, which it keeps (or
  /// adds): the pattern of a matrix whose state i is cut out of the coupling.
  void decouple(int i) {
    for (int r = 0; r < N; ++r) {
      if (r == i) {
        cols_[idx(r)][0] = static_cast<std::uint8_t>(i);
        count_[idx(r)] = 1;
        continue;
      }
      int kept = 0;
      for (int n = 0; n < count(r); ++n) {
        if (col(r, n) != i) cols_[idx(r)][idx(kept++)] = cols_[idx(r)][idx(n)];
      }
      count_[idx(r)] = kept;
    }
  }

  /// Whether no element lies below the leading `lead` x `lead` block's columns: rows from
  /// `lead` on reach no column before it (A = [A11 A12; 0 A22]).
  bool isBlockUpperTriangular(int lead) const {
    for (int i = lead; i < N; ++i)
      for (int n = 0; n < count(i); ++n)
        if (col(i, n) < lead) return false;
    return true;
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

  /// out += scale A B for a sparse B: only the products of nonzero elements, in place (no
  /// temporary to zero and add).
  void addProductTo(const SparseRows& B, double scale, Square& out) const {
    for (int i = 0; i < N; ++i) {
      for (int n = 0; n < p_->count(i); ++n) {
        const int k = p_->col(i, n);
        const double a = scale * a_(i, k);
        for (int m = 0; m < B.p_->count(k); ++m) {
          const int j = B.p_->col(k, m);
          out(i, j) += a * B.a_(k, j);
        }
      }
    }
  }

  /// A P A^T for a symmetric P and a block upper triangular A = [A11 A12; 0 A22], with A11
  /// Lead x Lead (the pattern says so: isBlockUpperTriangular(Lead)). Each step is a sum of
  /// contiguous columns (vectorized axpys), and only the products the block structure does not
  /// make zero or redundant are formed:
  ///   W = A(0:Lead, :) P                       (the leading rows of A P)
  ///   out(0:Lead, j) = W A(j, :)^T             (every column j: the leading rows of A P A^T)
  ///   out(Lead:, Lead:) = A22 P22 A22^T        (A's trailing rows reach trailing columns only)
  /// and the rest mirrored, so the result is symmetric to the last bit.
  template <int Lead>
  Square sandwichBlockTriangular(const Square& P) const {
    static_assert(Lead > 0 && Lead < N, "the leading block must be a proper one");
    constexpr int Trail = N - Lead;
    assert(p_->isBlockUpperTriangular(Lead));
    Eigen::Matrix<double, N, Lead> Wt;  // W^T = P A(0:Lead, :)^T
    for (int i = 0; i < Lead; ++i) Wt.col(i) = sumOfColumns(i, P);
    const Eigen::Matrix<double, Lead, N> W = Wt.transpose();
    Square out;
    for (int j = 0; j < N; ++j) out.col(j).template head<Lead>() = sumOfColumns(j, W);
    Eigen::Matrix<double, Trail, Trail> Tt;  // P22 A22^T
    const auto P22 = P.template bottomRightCorner<Trail, Trail>();
    for (int i = Lead; i < N; ++i) Tt.col(i - Lead) = sumOfColumns(i, P22, Lead);
    const Eigen::Matrix<double, Trail, Trail> T = Tt.transpose();
    for (int j = Lead; j < N; ++j) out.col(j).template tail<Trail>() = sumOfColumns(j, T, Lead);
    out.template bottomLeftCorner<Trail, Lead>() =
        out.template topRightCorner<Lead, Trail>().transpose();
    for (int j = 0; j < N; ++j) {
      for (int i = j + 1; i < (j < Lead ? Lead : N); ++i) out(i, j) = out(j, i);
    }
    return out;
  }

  /// B A^T: column i = sum_k A(i, k) B(:, k).
  Square timesTransposed(const Square& B) const {
    Square out;
    for (int i = 0; i < N; ++i) out.col(i) = sumOfColumns(i, B);
    return out;
  }

  /// B A^T for A block upper triangular at `Lead` ([A11 A12; 0 A22]) and B its transpose's
  /// kind, block lower triangular ([B11 0; B21 B22]; the transpose of a product of such A):
  /// the leading columns as timesTransposed(), the trailing ones only on the trailing rows
  /// (A22's rows reach B's trailing columns, whose leading rows are 0). A running product
  /// of transition matrices kept transposed (C^T <- C^T A^T) costs this instead of a dense
  /// product and two transposes.
  template <int Lead>
  Square timesTransposedBlockTriangular(const Square& B) const {
    static_assert(Lead > 0 && Lead < N, "the leading block must be a proper one");
    constexpr int Trail = N - Lead;
    assert(p_->isBlockUpperTriangular(Lead));
    Square out;
    for (int i = 0; i < Lead; ++i) out.col(i) = sumOfColumns(i, B);
    const auto B2 = B.template bottomRows<Trail>();
    for (int i = Lead; i < N; ++i) {
      out.col(i).template head<Lead>().setZero();
      Eigen::Matrix<double, Trail, 1> c = Eigen::Matrix<double, Trail, 1>::Zero();
      for (int n = 0; n < p_->count(i); ++n) {
        const int k = p_->col(i, n);
        c += a_(i, k) * B2.col(k);
      }
      out.col(i).template tail<Trail>() = c;
    }
    return out;
  }

  /// Elements of A in its pattern.
  int nonZeros() const { return p_->nonZeros(); }

 private:
  static std::size_t idx(int i) { return static_cast<std::size_t>(i); }

  /// sum_k A(i, k) B(:, k - offset) over row i's elements: column i of B A^T, for a B whose
  /// columns start at state `offset`.
  template <class Matrix>
  Eigen::Matrix<double, Matrix::RowsAtCompileTime, 1> sumOfColumns(int i, const Matrix& B,
                                                                   int offset = 0) const {
    Eigen::Matrix<double, Matrix::RowsAtCompileTime, 1> c;
    c.setZero();
    for (int n = 0; n < p_->count(i); ++n) {
      const int k = p_->col(i, n);
      c += a_(i, k) * B.col(k - offset);
    }
    return c;
  }

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
