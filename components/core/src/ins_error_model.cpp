#include "navbus/core/ins_error_model.hpp"

#include <cmath>

#include "navbus/core/rotation.hpp"
#include "navbus/core/sparse_rows.hpp"

namespace navbus::core {

Matrix17 errorDynamics(const NavState& s, const Eigen::Vector3d& f_b, earth::GravityModel gravity) {
  using namespace tc17;
  const Eigen::Matrix3d C_b_n = s.q_b_to_n.toRotationMatrix();
  const Eigen::Vector3d f_n = C_b_n * f_b;
  const Eigen::Vector3d w_ie = earth::omegaIeNed(s.position.latitude_rad);
  const Eigen::Vector3d w_en = earth::omegaEnNed(s.position, s.vel_ned_mps);
  const earth::Radii r = earth::radiiOfCurvature(s.position.latitude_rad);
  const double rn = r.prime_vertical_m + s.position.height_m;
  const double rm = r.meridian_m + s.position.height_m;
  const double g = earth::gravityNed(gravity, s.position).z();
  const double radius = std::sqrt(rm * rn);

  Matrix17 F = Matrix17::Zero();
  F.block<3, 3>(kPos.index, kPos.index) = -skew(w_en);
  F.block<3, 3>(kPos.index, kVel.index) = Eigen::Matrix3d::Identity();
  F.block<3, 3>(kVel.index, kAtt.index) = skew(f_n);
  F.block<3, 3>(kVel.index, kVel.index) = -skew(2.0 * w_ie + w_en);
  F.block<3, 3>(kVel.index, kAccelBias.index) = -C_b_n;
  F(kVel.index + 2, kPos.index + 2) = 2.0 * g / radius;  // gravity grows downwards
  F.block<3, 3>(kAtt.index, kAtt.index) = -skew(w_ie + w_en);
  // Transport rate from velocity errors: w_en = [vE / rn, -vN / rm, -vE tan(lat) / rn].
  Eigen::Matrix3d dwen_dv = Eigen::Matrix3d::Zero();
  dwen_dv(0, 1) = 1.0 / rn;
  dwen_dv(1, 0) = -1.0 / rm;
  dwen_dv(2, 1) = -std::tan(s.position.latitude_rad) / rn;
  F.block<3, 3>(kAtt.index, kVel.index) = dwen_dv;
  F.block<3, 3>(kAtt.index, kGyroBias.index) = C_b_n;
  F(kClockBias.index, kClockDrift.index) = 1.0;
  return F;
}

Matrix17 transitionMatrix(const Matrix17& F, double dt) {
  const Matrix17 Fdt = F * dt;
  const SparseRows<tc17::kSize> sparse(Fdt, errorDynamicsPattern());
  return Matrix17::Identity() + Fdt + 0.5 * sparse.times(sparse);
}

namespace {
/// F at a state where every term of errorDynamics() is nonzero: off the equator and the
/// meridians, moving in all three axes, rotated about a skew axis, a specific force with
/// three components.
Matrix17 genericErrorDynamics() {
  NavState s;
  s.position = {0.6, 2.2, 1000.0};
  s.vel_ned_mps = Eigen::Vector3d(120.0, -80.0, 15.0);
  s.q_b_to_n = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  return errorDynamics(s, Eigen::Vector3d(0.3, -0.2, -9.7), earth::GravityModel::kWgs84Normal);
}
}  // namespace

const SparsityPattern<tc17::kSize>& errorDynamicsPattern() {
  static const auto pattern = SparsityPattern<tc17::kSize>::of(genericErrorDynamics());
  return pattern;
}

const SparsityPattern<tc17::kSize>& transitionPattern() {
  // Magnitudes, so that no sum cancels to an accidental zero.
  static const auto pattern = [] {
    const Matrix17 A = genericErrorDynamics().cwiseAbs();
    return SparsityPattern<tc17::kSize>::of(Matrix17::Identity() + A + A * A);
  }();
  return pattern;
}

}  // namespace navbus::core
