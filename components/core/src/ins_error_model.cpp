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
  const SparseRows<tc17::kSize> sparse(Fdt);
  return Matrix17::Identity() + Fdt + 0.5 * sparse.times(sparse);
}

}  // namespace navbus::core
