// Static coarse alignment (see the header for the references).
//
// Derivation, with the step numbers the code cites. At rest on the Earth, in NED:
//   (1) f_ib^n  = -g^n = (0, 0, -g)                      specific force
//   (2) w_ib^n  = w_ie^n = (W cos L, 0, -W sin L)        inertial rate, W the Earth rate
// and the sensors read f^b = C_n^b f^n, w^b = C_n^b w^n with C_b^n = Rz(yaw) Ry(pitch) Rx(roll).
// Levelling, from (1) written out, f^b = g (sin p, -sin r cos p, -cos r cos p):
//   (3) roll  = atan2(-f_y, -f_z)
//   (4) pitch = atan2(f_x, sqrt(f_y^2 + f_z^2))
// Gyrocompassing: the rate in the levelled body frame, w^l = Ry(p) Rx(r) w^b, is
// Rz(yaw)^T w^n = (W cos L cos yaw, -W cos L sin yaw, -W sin L), so
//   (5) yaw = atan2(-w^l_y, w^l_x).
// Error budget (first order). An accelerometer error d_f along a horizontal body axis is read
// as a tilt d_f / g; the mean over T seconds of white noise of density VRW has sigma VRW/sqrt(T):
//   (6) sigma_level = sqrt(sigma_ba^2 + VRW^2 / T) / g.
// A gyro error d_w along the levelled east axis is read as a heading error d_w / (W cos L); a
// tilt d_t about north moves the vertical Earth rate W sin L into the east channel, a heading
// error d_t tan L:
//   (7) sigma_yaw^2 = r + r^2 + (sigma_level tan L)^2,  r = (sigma_bg^2 + ARW^2 / T) / (W cos L)^2.
// r^2 is the second order of (5): yaw error = atan2(d_w_E, W cos L + d_w_N), whose product term
// d_w_E d_w_N / (W cos L)^2 has variance r^2 for north and east errors of equal sigma. It is
// negligible where gyrocompassing is good and not where it is marginal: for 1 deg/h gyros at
// 36.5 deg, sqrt(r) = 83 mrad and sqrt(r^2) = 7 mrad, which the first order would claim known
// once the filter has learned the east gyro bias (measured: the heading error minus its first
// order had 8.9 mrad RMS over 100 seed-000 runs).
// (7) is what decides whether a gyro grade can gyrocompass: a 0.01 deg/h gyro at 45 deg
// latitude gives about 0.05 deg; a 10 deg/h MEMS gyro gives more than a radian (no heading).
// The same first order, as sensitivities of the attitude error phi (NED, C_b^n computed =
// (I - [phi x]) C_b^n true) to the true biases b_a, b_g (body), for a filter that starts with
// its attitude and bias errors correlated as they are. With b^n = C_b^n b, levelling makes the
// computed horizontal specific force vanish, b^n_h - (phi x f^n)_h = 0 with f^n from (1);
// gyrocompassing makes the computed east rate vanish, b_g^n_E - (phi x w^n)_E = 0 with (2):
//   (8) phi_N = b_a^n_E / g,  phi_E = -b_a^n_N / g,
//       phi_D = b_g^n_E / (W cos L) - phi_N tan L.
// Beyond the first order (what a filter started from (8) meets at rest): the gyros see the
// Earth rate of the true frame, C_n^n' w^n in the computed one n', and the mechanization takes
// w^n away, so the attitude drifts as under a gyro bias C_n'^b (exp(-[phi x]) - I) w^n. The
// error model has its first order -phi x w^n (the gyrocompassing coupling); a filter at rest
// learns the rest as a bias. For phi = (0, 0, psi), with (2):
//   (9) (exp(-[phi x]) - I + [phi x]) w^n = W cos L (cos psi - 1, psi - sin psi, 0),
// 0.44 deg/h on the north channel at psi = 0.27 rad and 36.5 deg (seed 000's 3-sigma heading).
// While psi is known only as N(0, s^2), E[cos psi] = e^(-s^2/2), E[cos^2 psi] = (1 + e^(-2s^2))/2:
//   (10) Var(W cos L (cos psi - 1)) = (W cos L)^2 (1 - e^(-s^2))^2 / 2,
// 0.059 deg/h (1 sigma) at s = 83 mrad, where the filter would claim 0.014 deg/h.
#include "navbus/core/ins/static_alignment.hpp"

#include <cmath>
#include <limits>

#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/rotation.hpp"

namespace navbus::core {

namespace {
/// Below this |cos L| (about 0.2" from a pole) the horizontal Earth rate points nowhere.
constexpr double kMinCosLatitude = 1e-6;
}  // namespace

void StaticWindow::add(const ImuIncrement& inc) {
  sum_delta_vel_b_mps_ += inc.delta_vel_b_mps;
  sum_delta_angle_b_rad_ += inc.delta_angle_b_rad;
  duration_s_ += inc.interval_s;
  ++count_;
}

void StaticWindow::add(const StaticWindow& later) {
  sum_delta_vel_b_mps_ += later.sum_delta_vel_b_mps_;
  sum_delta_angle_b_rad_ += later.sum_delta_angle_b_rad_;
  duration_s_ += later.duration_s_;
  count_ += later.count_;
}

Eigen::Vector3d StaticWindow::meanSpecificForce_b_mps2() const {
  return duration_s_ > 0.0 ? Eigen::Vector3d(sum_delta_vel_b_mps_ / duration_s_)
                           : Eigen::Vector3d::Zero();
}

Eigen::Vector3d StaticWindow::meanRate_ib_b_radps() const {
  return duration_s_ > 0.0 ? Eigen::Vector3d(sum_delta_angle_b_rad_ / duration_s_)
                           : Eigen::Vector3d::Zero();
}

double levellingSigma(const AlignmentErrorBudget& budget, double duration_s, double gravity_mps2) {
  if (!(duration_s > 0.0)) return std::numeric_limits<double>::infinity();
  const double vrw = budget.velocity_random_walk_mps_per_sqrts;
  const double bias = budget.accel_bias_sigma_mps2;
  return std::sqrt(bias * bias + vrw * vrw / duration_s) / gravity_mps2;  // (6)
}

double gyrocompassingHeadingSigma(const AlignmentErrorBudget& budget, double duration_s,
                                  double latitude_rad, double level_sigma_rad) {
  const double horizontal_rate = earth::kRotationRate_radps * std::cos(latitude_rad);
  if (!(duration_s > 0.0) ||
      std::abs(horizontal_rate) < earth::kRotationRate_radps * kMinCosLatitude) {
    return std::numeric_limits<double>::infinity();
  }
  const double arw = budget.angle_random_walk_rad_per_sqrts;
  const double bias = budget.gyro_bias_sigma_radps;
  const double rate_term =
      (bias * bias + arw * arw / duration_s) / (horizontal_rate * horizontal_rate);
  const double tilt_term = level_sigma_rad * std::tan(latitude_rad);
  return std::sqrt(rate_term + rate_term * rate_term + tilt_term * tilt_term);  // (7)
}

CoarseAlignment alignStatic(const StaticWindow& window, double latitude_rad, double gravity_mps2,
                            const AlignmentErrorBudget& budget, double max_heading_sigma_rad) {
  const Eigen::Vector3d f = window.meanSpecificForce_b_mps2();
  const double roll = std::atan2(-f.y(), -f.z());                    // (3)
  const double pitch = std::atan2(f.x(), std::hypot(f.y(), f.z()));  // (4)

  CoarseAlignment out;
  out.level_sigma_rad = levellingSigma(budget, window.duration_s(), gravity_mps2);
  out.heading_sigma_rad =
      gyrocompassingHeadingSigma(budget, window.duration_s(), latitude_rad, out.level_sigma_rad);
  double yaw = 0.0;
  if (!(window.duration_s() > 0.0)) {
    out.heading_limit = HeadingLimit::kNoData;
  } else if (std::abs(std::cos(latitude_rad)) < kMinCosLatitude) {
    out.heading_limit = HeadingLimit::kNearPole;
  } else if (out.heading_sigma_rad > max_heading_sigma_rad) {
    out.heading_limit = HeadingLimit::kGyroGrade;
  } else {
    const Eigen::Vector3d w_l =
        Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
        (Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()) * window.meanRate_ib_b_radps());
    yaw = std::atan2(-w_l.y(), w_l.x());  // (5)
  }
  out.roll_pitch_yaw_rad = Eigen::Vector3d(roll, pitch, yaw);
  out.q_b_to_n = Eigen::Quaterniond(dcmFromEuler(out.roll_pitch_yaw_rad)).normalized();
  return out;
}

AlignmentSensitivity alignmentSensitivity(const Eigen::Matrix3d& C_b_n, double latitude_rad,
                                          double gravity_mps2, bool heading_from_gyros) {
  AlignmentSensitivity out;
  const Eigen::RowVector3d north = C_b_n.row(0) / gravity_mps2;
  const Eigen::RowVector3d east = C_b_n.row(1) / gravity_mps2;
  out.d_att_d_accel_bias_b.row(0) = east;    // (8) phi_N
  out.d_att_d_accel_bias_b.row(1) = -north;  // (8) phi_E
  const double horizontal_rate = earth::kRotationRate_radps * std::cos(latitude_rad);
  if (heading_from_gyros && std::abs(std::cos(latitude_rad)) >= kMinCosLatitude) {
    out.d_att_d_accel_bias_b.row(2) = -std::tan(latitude_rad) * east;  // (8) phi_D, tilt
    out.d_att_d_gyro_bias_b.row(2) = C_b_n.row(1) / horizontal_rate;   // (8) phi_D, gyro
  }
  return out;
}

EarthRateMismatch earthRateMismatchRemainder(double psi_rad,
                                             const Eigen::Vector3d& w_ie_ned_radps) {
  const double horizontal_rate = w_ie_ned_radps.head<2>().norm();  // W cos L
  EarthRateMismatch out;
  out.remainder_radps =
      horizontal_rate * Eigen::Vector3d(std::cos(psi_rad) - 1.0, psi_rad - std::sin(psi_rad), 0.0);
  out.d_remainder_d_psi =
      horizontal_rate * Eigen::Vector3d(-std::sin(psi_rad), 1.0 - std::cos(psi_rad), 0.0);  // d(9)
  return out;
}

double earthRateRemainderNorthVariance(double var_psi_rad2, const Eigen::Vector3d& w_ie_ned_radps) {
  const double spread = w_ie_ned_radps.head<2>().norm() * (1.0 - std::exp(-var_psi_rad2));
  return 0.5 * spread * spread;  // (10)
}

}  // namespace navbus::core
