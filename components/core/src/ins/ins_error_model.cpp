#include "navbus/core/ins/ins_error_model.hpp"

#include <array>
#include <cmath>

#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/sparse_rows.hpp"

namespace navbus::core {

StateMatrix errorDynamics(const NavState& s, const Eigen::Vector3d& f_b,
                          const Eigen::Vector3d& w_ib_b, earth::GravityModel gravity) {
  return errorDynamics(s, f_b, w_ib_b, earth::localEarth(gravity, s.position, s.vel_ned_mps));
}

StateMatrix errorDynamics(const NavState& s, const Eigen::Vector3d& f_b,
                          const Eigen::Vector3d& w_ib_b, const earth::LocalEarth& at_state) {
  return errorDynamics(errorDynamicsBlocks(s, f_b, w_ib_b, at_state));
}

ErrorDynamicsBlocks errorDynamicsBlocks(const NavState& s, const Eigen::Vector3d& f_b,
                                        const Eigen::Vector3d& w_ib_b,
                                        const earth::LocalEarth& at_state) {
  const Eigen::Matrix3d C_b_n = s.q_b_to_n.toRotationMatrix();
  const Eigen::Vector3d f_n = C_b_n * f_b;
  const Eigen::Vector3d& w_ie = at_state.w_ie_ned;
  const earth::Radii& r = at_state.radii;
  const Eigen::Vector3d& w_en = at_state.w_en_ned;
  const double rn = r.prime_vertical_m + s.position.height_m;
  const double rm = r.meridian_m + s.position.height_m;
  const double g = at_state.g_ned.z();
  const double radius = std::sqrt(rm * rn);

  const Eigen::Vector3d& v = s.vel_ned_mps;
  const double w_ie_n = w_ie.x();  // Omega cos(lat)
  const double w_ie_d = w_ie.z();  // -Omega sin(lat)
  const double tan_lat = -w_ie_d / w_ie_n;
  const double sec2_lat = 1.0 + tan_lat * tan_lat;
  // The position error is in NED metres of the curvilinear position: dN = (R_M + h) dlat,
  // dE = (R_N + h) cos(lat) dlon, dD = -dh. The Earth and transport rates depend on the
  // position through lat and h:
  //   w_ie = Omega [cos lat, 0, -sin lat],  w_en = [vE / rn, -vN / rm, -vE tan(lat) / rn],
  // so d(w)/d(dN) = d(w)/d(lat) / rm and d(w)/d(dD) = -d(w)/d(h) (radii's latitude terms, of
  // the order of the flattening, left out).
  Eigen::Matrix3d dwie_dr = Eigen::Matrix3d::Zero();
  dwie_dr(0, 0) = w_ie_d / rm;
  dwie_dr(2, 0) = -w_ie_n / rm;
  Eigen::Matrix3d dwen_dr = Eigen::Matrix3d::Zero();
  dwen_dr(2, 0) = -v.y() * sec2_lat / (rn * rm);
  dwen_dr(0, 2) = v.y() / (rn * rn);
  dwen_dr(1, 2) = -v.x() / (rm * rm);
  dwen_dr(2, 2) = -v.y() * tan_lat / (rn * rn);
  // ... and w_en on the velocity.
  Eigen::Matrix3d dwen_dv = Eigen::Matrix3d::Zero();
  dwen_dv(0, 1) = 1.0 / rn;
  dwen_dv(1, 0) = -1.0 / rm;
  dwen_dv(2, 1) = -tan_lat / rn;

  ErrorDynamicsBlocks F;
  // Position (the curvilinear rates lat' = vN / rm, lon' = vE / (rn cos lat), h' = -vD, in the
  // metres above): dN' = dvN + (vN dD - vD dN) / rm,
  // dE' = dvE + vE tan(lat) dN / rm - (vD + vN tan(lat)) dE / rn + vE dD / rn, dD' = dvD.
  F.pos_pos.setZero();
  F.pos_pos(0, 0) = -v.z() / rm;
  F.pos_pos(0, 2) = v.x() / rm;
  F.pos_pos(1, 0) = v.y() * tan_lat / rm;
  F.pos_pos(1, 1) = -(v.z() + v.x() * tan_lat) / rn;
  F.pos_pos(1, 2) = v.y() / rn;
  // Velocity, v' = C f - (2 w_ie + w_en) x v + g: the perturbation of the Coriolis and transport
  // term is -(2 w_ie + w_en) x dv + v x (2 dw_ie + dw_en).
  F.vel_pos = skew(v) * (2.0 * dwie_dr + dwen_dr);
  F.vel_pos(2, 2) += 2.0 * g / radius;  // gravity grows downwards
  F.vel_vel = -skew(2.0 * w_ie + w_en) + skew(v) * dwen_dv;
  F.vel_att = skew(f_n);
  F.vel_accel_bias = -C_b_n;
  F.vel_accel_scale = -C_b_n * f_b.asDiagonal();
  // Attitude, phi' = -w_in x phi + dw_in + C_b_n e_g.
  F.att_pos = dwie_dr + dwen_dr;
  F.att_vel = dwen_dv;
  F.att_att = -skew(w_ie + w_en);
  F.att_gyro_bias = C_b_n;
  F.att_gyro_scale = C_b_n * w_ib_b.asDiagonal();
  return F;
}

namespace {
/// The blocks of ErrorDynamicsBlocks, for the operations that treat them alike.
constexpr std::array<Eigen::Matrix3d ErrorDynamicsBlocks::*, 11> kBlocks{
    &ErrorDynamicsBlocks::pos_pos,        &ErrorDynamicsBlocks::vel_pos,
    &ErrorDynamicsBlocks::vel_vel,        &ErrorDynamicsBlocks::vel_att,
    &ErrorDynamicsBlocks::vel_accel_bias, &ErrorDynamicsBlocks::vel_accel_scale,
    &ErrorDynamicsBlocks::att_pos,        &ErrorDynamicsBlocks::att_vel,
    &ErrorDynamicsBlocks::att_att,        &ErrorDynamicsBlocks::att_gyro_bias,
    &ErrorDynamicsBlocks::att_gyro_scale};
}  // namespace

ErrorDynamicsBlocks& ErrorDynamicsBlocks::operator*=(double s) {
  for (const auto block : kBlocks) this->*block *= s;
  constant *= s;
  return *this;
}

void ErrorDynamicsBlocks::addScaled(const ErrorDynamicsBlocks& b, double s) {
  for (const auto block : kBlocks) this->*block += s * (b.*block);
  constant += s * b.constant;
}

StateMatrix errorDynamics(const ErrorDynamicsBlocks& b) {
  using namespace layout;
  StateMatrix F = StateMatrix::Zero();
  F.block<3, 3>(kPos.index, kPos.index) = b.pos_pos;
  F.block<3, 3>(kPos.index, kVel.index) = b.constant * Eigen::Matrix3d::Identity();
  F.block<3, 3>(kVel.index, kPos.index) = b.vel_pos;
  F.block<3, 3>(kVel.index, kVel.index) = b.vel_vel;
  F.block<3, 3>(kVel.index, kAtt.index) = b.vel_att;
  F.block<3, 3>(kVel.index, kAccelBias.index) = b.vel_accel_bias;
  F.block<3, 3>(kVel.index, kAccelScale.index) = b.vel_accel_scale;
  F.block<3, 3>(kAtt.index, kPos.index) = b.att_pos;
  F.block<3, 3>(kAtt.index, kVel.index) = b.att_vel;
  F.block<3, 3>(kAtt.index, kAtt.index) = b.att_att;
  F.block<3, 3>(kAtt.index, kGyroBias.index) = b.att_gyro_bias;
  F.block<3, 3>(kAtt.index, kGyroScale.index) = b.att_gyro_scale;
  F(kClockBias.index, kClockDrift.index) = b.constant;
  F(kSecondClockBias.index, kSecondClockDrift.index) = b.constant;
  return F;
}

StateMatrix transitionMatrix(const StateMatrix& F, double dt) {
  // I + F dt + (F dt)^2 / 2 = I + dt (F + (dt / 2) F F): the sparse product accumulates into
  // a copy of F, and the identity is added on the diagonal (Eigen's StateMatrix::Identity()
  // expression tests i == j for each of the 400 elements, which cost as much as the product).
  const SparseRows<layout::kSize> sparse(F, errorDynamicsPattern());
  StateMatrix Phi = F;
  sparse.addProductTo(sparse, 0.5 * dt, Phi);
  Phi *= dt;
  Phi.diagonal().array() += 1.0;
  return Phi;
}

namespace {
/// F at a state where every term of errorDynamics() is nonzero: off the equator and the
/// meridians, moving in all three axes, rotated about a skew axis, a specific force and an
/// angular rate with three components.
StateMatrix genericErrorDynamics() {
  NavState s;
  s.position = {0.6, 2.2, 1000.0};
  s.vel_ned_mps = Eigen::Vector3d(120.0, -80.0, 15.0);
  s.q_b_to_n = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  return errorDynamics(s, Eigen::Vector3d(0.3, -0.2, -9.7), Eigen::Vector3d(0.01, -0.02, 0.03),
                       earth::GravityModel::kWgs84Normal);
}
}  // namespace

const SparsityPattern<layout::kSize>& errorDynamicsPattern() {
  static const auto pattern = SparsityPattern<layout::kSize>::of(genericErrorDynamics());
  return pattern;
}

const SparsityPattern<layout::kSize>& transitionPattern() {
  // Magnitudes, so that no sum cancels to an accidental zero.
  static const auto pattern = [] {
    const StateMatrix A = genericErrorDynamics().cwiseAbs();
    return SparsityPattern<layout::kSize>::of(StateMatrix::Identity() + A + A * A);
  }();
  return pattern;
}

}  // namespace navbus::core
