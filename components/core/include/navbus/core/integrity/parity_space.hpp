// The parity space of redundant instruments (Potter and Suman, "Thresholdless redundancy
// management with arrays of skewed instruments", 1977; Sturza, "Navigation system integrity
// monitoring using redundant measurements", 1988). n >= 4 single-axis instruments (or k triads,
// 3k axes) sense one 3-vector x (angular rate or specific force, in a common frame):
//
//   m = H x + b + e,   H (n x 3): the unit sensing axes, b the instruments' faults,
//                      e the noises, independent, sigma_i per sample.                    (1)
//
// Whitened by W = diag(1 / sigma_i), the parity matrix V ((n - 3) x n) spans the left null space
// of W H with orthonormal rows (V W H = 0, V V^T = I), so the parity vector
//
//   p = V W m = V W b + V W e                                                            (2)
//
// does not depend on x and has unit covariance without fault. A bias b_j on instrument j moves p
// along its signature s_j = V W e_j = V(:, j) / sigma_j: detection tests |p|, isolation compares
// p with each s_j (Sturza eqs. 10-13; the window test over many samples is parity_glr.hpp).
// Instruments whose signatures are (nearly) collinear cannot be told apart (two parallel
// triads: the x axes of the two units have opposite signatures). The least-squares estimate
// x^ = (H^T W^2 H)^-1 H^T W^2 m combines all instruments.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

namespace navbus::core {

namespace parity {
inline constexpr int kMaxInstruments = 18;  ///< six triads, or 18 single-axis instruments
inline constexpr int kMaxParity = kMaxInstruments - 1;  ///< one common unknown (makeCommonMode)
using Axes = Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxInstruments, 3>;
using Measurements = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxInstruments, 1>;
using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxParity, 1>;
using Matrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxParity, kMaxInstruments>;
}  // namespace parity

class ParitySpace {
 public:
  /// The parity space of instruments with these sensing axes (rows, normalised here) and noise
  /// sigmas per sample; nullopt with `error` set (naming the instrument or the condition) when
  /// there are fewer than 4 or more than kMaxInstruments, an axis is zero or not finite, a sigma
  /// is not positive, or the axes do not span three dimensions.
  static std::optional<ParitySpace> make(const parity::Axes& axes,
                                         const parity::Measurements& sigmas, std::string& error);
  /// The parity space of instruments that all measure one common unknown (H a column of ones:
  /// e.g. two receivers' pseudorange differences of their shared satellites, whose common part
  /// is the difference of their clocks); nullopt with `error` set when there are fewer than 2 or
  /// more than kMaxInstruments, or a sigma is not positive. estimate() gives the unknown in x[0].
  static std::optional<ParitySpace> makeCommonMode(const parity::Measurements& sigmas,
                                                   std::string& error);

  int instruments() const { return static_cast<int>(axes_.rows()); }
  int dimension() const { return instruments() - unknowns_; }  ///< n - 3 (n - 1: common mode)
  const parity::Axes& axes() const { return axes_; }
  const parity::Measurements& sigmas() const { return sigmas_; }
  /// V W (eq. 2): (n - 3) x n; its column j is s_j = V W e_j, the parity vector of a unit bias
  /// on instrument j.
  const parity::Matrix& parityMatrix() const { return vw_; }
  /// |s_j|^2: the information a sample carries on a bias of instrument j [1 / unit^2].
  double information(int j) const { return vw_.col(j).squaredNorm(); }
  /// |s_i . s_j| / (|s_i| |s_j|): 1 when instruments i and j cannot be told apart.
  double signatureCorrelation(int i, int j) const;

  /// p = V W m (eq. 2).
  parity::Vector parityVector(const parity::Measurements& m) const;
  /// x^ = (H^T W^2 H)^-1 H^T W^2 m: every instrument, weighted by 1 / sigma^2 (with one common
  /// unknown: x[0], the rest 0).
  Eigen::Vector3d estimate(const parity::Measurements& m) const { return estimator_ * m; }
  /// The covariance of estimate() from the instruments' noise, (H^T W^2 H)^-1.
  Eigen::Matrix3d estimateCovariance() const {
    return estimator_ * sigmas_.cwiseAbs2().asDiagonal() * estimator_.transpose();
  }

 private:
  ParitySpace() = default;
  /// V W and the estimator from the whitened geometry W H of `unknowns` columns (eq. 2).
  bool build(const parity::Axes& wh, int unknowns, std::string& error);
  int unknowns_{3};
  parity::Axes axes_;
  parity::Measurements sigmas_;
  parity::Matrix vw_;
  Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, parity::kMaxInstruments> estimator_;
};

}  // namespace navbus::core
