// Innovation-based adaptive estimation of the measurement noise (seed 001 eqs. 30-34): the
// innovation covariance is estimated from a sliding window of innovations,
//   C_k = 1/N sum dz_i dz_i^T                      (eq. 31 over the last N epochs),
//   R_k = C_k - H P- H^T                           (eqs. 32, 34),
// and every variance that comes out at or below the floor xi is replaced by xi (eq. 33).
// Optionally the floor is also the measurement's own reported variance: R then only grows
// (a sensor noisier than it says, or a fault), and a window of 20 innovations, whose sample
// variance scatters by +-30 %, never makes the filter trust a sensor more than its report.
// The paper accumulates from the start (1/k); a window lets R fall back after a fault ends.
// Only the diagonal of R is estimated: off-diagonal sample covariances of a short window are
// noise, and a diagonal R keeps the update's row decorrelation exact.
#pragma once

#include <array>

#include <Eigen/Core>

namespace navbus::core {

template <int M>
class InnovationWindow {
 public:
  static constexpr int kMaxLength = 256;  ///< fixed storage: no allocation in the loop
  using Vector = Eigen::Matrix<double, M, 1>;
  using Matrix = Eigen::Matrix<double, M, M>;

  /// length: N epochs (1..kMaxLength); floor_sigma: sqrt(xi) per component.
  void configure(int length, const Vector& floor_sigma) {
    length_ = length < 1 ? 1 : (length > kMaxLength ? kMaxLength : length);
    floor_var_ = floor_sigma.array().square().matrix();
    clear();
  }
  void clear() {
    count_ = 0;
    next_ = 0;
  }
  /// Adds the innovation dz = z - H x- of one epoch (eq. 30).
  void push(const Vector& dz) {
    samples_[static_cast<std::size_t>(next_)] = dz;
    next_ = (next_ + 1) % length_;
    if (count_ < length_) ++count_;
  }
  /// True once the window holds N innovations; before that the nominal R is used.
  bool full() const { return count_ == length_; }

  /// The adapted R given H P- H^T (eqs. 31-34), diagonal; `reported` (the measurement's own
  /// R), when given, is a floor too.
  Matrix adaptedR(const Matrix& hpht, const Matrix* reported = nullptr) const {
    Vector c = Vector::Zero();
    for (int i = 0; i < count_; ++i) {
      c += samples_[static_cast<std::size_t>(i)].array().square().matrix();
    }
    c /= static_cast<double>(count_ > 0 ? count_ : 1);
    Matrix r = Matrix::Zero();
    for (int j = 0; j < M; ++j) {
      const double v = c[j] - hpht(j, j);
      double floor = floor_var_[j];
      if (reported != nullptr && (*reported)(j, j) > floor) floor = (*reported)(j, j);
      r(j, j) = v > floor ? v : floor;
    }
    return r;
  }

 private:
  std::array<Vector, kMaxLength> samples_{};
  Vector floor_var_{Vector::Zero()};
  int length_{1};
  int count_{0};
  int next_{0};
};

}  // namespace navbus::core
