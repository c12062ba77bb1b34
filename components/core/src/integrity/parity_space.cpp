#include "navbus/core/integrity/parity_space.hpp"

#include <cmath>

#include <Eigen/LU>
#include <Eigen/QR>

namespace navbus::core {

using namespace parity;

std::optional<ParitySpace> ParitySpace::make(const Axes& axes, const Measurements& sigmas,
                                             std::string& error) {
  const int n = static_cast<int>(axes.rows());
  if (n < 4 || n > kMaxInstruments) {
    error = "parity space: " + std::to_string(n) + " instruments; it needs 4 to " +
            std::to_string(kMaxInstruments) + " (3 axes estimate x, the rest are parity)";
    return std::nullopt;
  }
  if (sigmas.size() != n) {
    error = "parity space: " + std::to_string(sigmas.size()) + " noise sigmas for " +
            std::to_string(n) + " instruments";
    return std::nullopt;
  }
  ParitySpace ps;
  ps.axes_ = axes;
  ps.sigmas_ = sigmas;
  for (int i = 0; i < n; ++i) {
    const double norm = axes.row(i).norm();
    if (!std::isfinite(norm) || !(norm > 0.0)) {
      error = "parity space: instrument " + std::to_string(i) + " has no sensing axis";
      return std::nullopt;
    }
    if (!(sigmas[i] > 0.0) || !std::isfinite(sigmas[i])) {
      error = "parity space: instrument " + std::to_string(i) + " has noise sigma " +
              std::to_string(sigmas[i]) + "; it must be positive";
      return std::nullopt;
    }
    ps.axes_.row(i) /= norm;
  }
  // Whitened geometry W H (eq. 2).
  if (!ps.build(sigmas.cwiseInverse().asDiagonal() * ps.axes_, 3, error)) return std::nullopt;
  return ps;
}

std::optional<ParitySpace> ParitySpace::makeCommonMode(const Measurements& sigmas,
                                                       std::string& error) {
  const int n = static_cast<int>(sigmas.size());
  if (n < 2 || n > kMaxInstruments) {
    error = "parity space: " + std::to_string(n) +
            " instruments of a common unknown; it needs 2 to " + std::to_string(kMaxInstruments);
    return std::nullopt;
  }
  for (int i = 0; i < n; ++i) {
    if (!(sigmas[i] > 0.0) || !std::isfinite(sigmas[i])) {
      error = "parity space: instrument " + std::to_string(i) + " has noise sigma " +
              std::to_string(sigmas[i]) + "; it must be positive";
      return std::nullopt;
    }
  }
  ParitySpace ps;
  ps.axes_ = Axes::Zero(n, 3);
  ps.axes_.col(0).setOnes();
  ps.sigmas_ = sigmas;
  if (!ps.build(sigmas.cwiseInverse().asDiagonal() * ps.axes_, 1, error)) return std::nullopt;
  return ps;
}

bool ParitySpace::build(const Axes& wh_full, int unknowns, std::string& error) {
  const int n = static_cast<int>(wh_full.rows());
  unknowns_ = unknowns;
  // Its full QR: Q's last n - k columns span the left null space of W H.
  using Geometry = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxInstruments, 3>;
  const Geometry wh = wh_full.leftCols(unknowns);
  const Eigen::HouseholderQR<Geometry> qr(wh);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3> r =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>::Zero(unknowns, unknowns);
  r.triangularView<Eigen::Upper>() = qr.matrixQR().topLeftCorner(unknowns, unknowns);
  if (!(std::abs(r.diagonal().prod()) > 1e-9 * wh.colwise().norm().prod())) {
    error = unknowns == 3 ? "parity space: the sensing axes do not span three dimensions"
                          : "parity space: the geometry is singular";
    return false;
  }
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxInstruments, kMaxInstruments>
      q = qr.householderQ();
  const Measurements w = sigmas_.cwiseInverse();
  vw_ = q.rightCols(n - unknowns).transpose() * w.asDiagonal();
  // x^ = (H^T W^2 H)^-1 H^T W^2 m = R^-1 Q1^T W m (eq. 3 in the header's terms).
  estimator_.setZero(3, n);
  estimator_.topRows(unknowns) = r.inverse() * q.leftCols(unknowns).transpose() * w.asDiagonal();
  return true;
}

double ParitySpace::signatureCorrelation(int i, int j) const {
  const double den = vw_.col(i).norm() * vw_.col(j).norm();
  return den > 0.0 ? std::abs(vw_.col(i).dot(vw_.col(j))) / den : 1.0;
}

Vector ParitySpace::parityVector(const Measurements& m) const {
  return vw_ * m;
}

}  // namespace navbus::core
