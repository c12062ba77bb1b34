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
  // Whitened geometry W H (eq. 2); its full QR: Q's last n - 3 columns span the left null space.
  const Axes wh = sigmas.cwiseInverse().asDiagonal() * ps.axes_;
  const Eigen::HouseholderQR<Axes> qr(wh);
  const Eigen::Matrix3d r = qr.matrixQR().topRows<3>().triangularView<Eigen::Upper>();
  if (!(std::abs(r.diagonal().prod()) > 1e-9 * wh.colwise().norm().prod())) {
    error = "parity space: the sensing axes do not span three dimensions";
    return std::nullopt;
  }
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxInstruments, kMaxInstruments>
      q = qr.householderQ();
  ps.vw_ = q.rightCols(n - 3).transpose() * sigmas.cwiseInverse().asDiagonal();
  // x^ = (H^T W^2 H)^-1 H^T W^2 m = R^-1 Q1^T W m (eq. 3 in the header's terms).
  ps.estimator_ = r.inverse() * q.leftCols<3>().transpose() * sigmas.cwiseInverse().asDiagonal();
  return ps;
}

double ParitySpace::signatureCorrelation(int i, int j) const {
  const double den = vw_.col(i).norm() * vw_.col(j).norm();
  return den > 0.0 ? std::abs(vw_.col(i).dot(vw_.col(j))) / den : 1.0;
}

Vector ParitySpace::parityVector(const Measurements& m) const {
  return vw_ * m;
}

}  // namespace navbus::core
