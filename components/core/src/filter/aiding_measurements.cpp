#include "navbus/core/filter/aiding_measurements.hpp"

#include <cmath>

#include "navbus/core/math/rotation.hpp"

namespace navbus::core {

using namespace layout;

VectorMeasurement positionMeasurement(const NavState& ins, const earth::Geodetic& fix,
                                      const Eigen::Vector3d& sigma,
                                      const Eigen::Vector3d& lever_arm_b,
                                      const Eigen::Vector3d* fix_error_ned_m) {
  VectorMeasurement m;
  const Eigen::Vector3d lever_n = ins.q_b_to_n * lever_arm_b;
  m.z = earth::differenceNed(ins.position, fix) + lever_n;
  m.h.setZero();
  m.h.block<3, 3>(0, kPos.index).setIdentity();
  m.h.block<3, 3>(0, kAtt.index) = skew(lever_n);
  if (fix_error_ned_m != nullptr) {
    m.z += *fix_error_ned_m;
    m.h.block<3, 3>(0, kFixPositionError.index).setIdentity();
  }
  m.r = sigma.array().square().matrix().asDiagonal();
  return m;
}

VectorMeasurement velocityMeasurement(const NavState& ins, const Eigen::Vector3d& fix_vel,
                                      const Eigen::Vector3d& sigma,
                                      const Eigen::Vector3d& lever_arm_b,
                                      const Eigen::Vector3d& rate_nb_b) {
  VectorMeasurement m;
  const Eigen::Vector3d lever_vel_n = ins.q_b_to_n * rate_nb_b.cross(lever_arm_b);
  m.z = ins.vel_ned_mps + lever_vel_n - fix_vel;
  m.h.setZero();
  m.h.block<3, 3>(0, kVel.index).setIdentity();
  m.h.block<3, 3>(0, kAtt.index) = skew(lever_vel_n);
  m.r = sigma.array().square().matrix().asDiagonal();
  return m;
}

VectorMeasurement attitudeMeasurement(const NavState& ins, const Eigen::Quaterniond& q_b_to_i,
                                      const Eigen::Vector3d& sigma_b,
                                      const Eigen::Vector3d& bias_estimate_b) {
  VectorMeasurement m;
  const double t_s = 1e-9 * static_cast<double>(ins.time_ns);
  const Eigen::Matrix3d C_n_e = earth::C_n_e(ins.position.latitude_rad, ins.position.longitude_rad);
  // Measured body-to-NED: C_b_n = C_e_n C_i_e C_b_i.
  const Eigen::Matrix3d C_meas =
      C_n_e.transpose() * earth::C_i_e(t_s) * q_b_to_i.toRotationMatrix();
  const Eigen::Matrix3d C_ins = ins.q_b_to_n.toRotationMatrix();
  // C_ins C_meas^T = (I - [phi x]) (I + [eps x]) ~ I - [(phi - eps) x]: z = vee of the negated
  // antisymmetric part.
  const Eigen::Matrix3d A = C_ins * C_meas.transpose();
  m.z = Eigen::Vector3d(A(1, 2) - A(2, 1), A(2, 0) - A(0, 2), A(0, 1) - A(1, 0)) / 2.0 -
        C_ins * bias_estimate_b;
  m.h.setZero();
  m.h.block<3, 3>(0, kAtt.index).setIdentity();
  m.h.block<3, 3>(0, kStarTrackerBias.index) = -C_ins;
  const Eigen::Matrix3d R_b = sigma_b.array().square().matrix().asDiagonal();
  m.r = C_ins * R_b * C_ins.transpose();
  return m;
}

VectorMeasurement zeroVelocityMeasurement(const NavState& ins, double sigma_mps) {
  VectorMeasurement m;
  m.z = ins.vel_ned_mps;
  m.h.setZero();
  m.h.block<3, 3>(0, kVel.index).setIdentity();
  m.r = Eigen::Matrix3d::Identity() * sigma_mps * sigma_mps;
  return m;
}

AidingMeasurement<2> nonHolonomicMeasurement(const NavState& ins, double sigma_mps,
                                             double velocity_pitch_b_rad,
                                             const Eigen::Vector3d* mounting_rad) {
  AidingMeasurement<2> m;
  // The vehicle's axes: (I - [mu x]) times the body's (the identity without mounting states).
  const Eigen::Matrix3d C_b_v =
      Eigen::Matrix3d::Identity() -
      (mounting_rad != nullptr ? skew(*mounting_rad) : Eigen::Matrix3d::Zero());
  const Eigen::Matrix3d C_n_b = ins.q_b_to_n.toRotationMatrix().transpose();
  const Eigen::Vector3d v_b = C_n_b * ins.vel_ned_mps;
  const Eigen::Vector3d v_v = C_b_v * v_b;
  // d(v_b)/d(dV) = C_n_b and d(v_b)/d(phi) = -C_n_b [V x], per body axis (row), turned into
  // the vehicle's axes; d(v_v)/d(d mu) = [v_b x].
  const Eigen::Matrix3d dvv_dv = C_b_v * C_n_b;
  const Eigen::Matrix3d dvv_dphi = -C_b_v * C_n_b * skew(ins.vel_ned_mps);
  const Eigen::Matrix3d dvv_dmu = skew(v_b);
  const double tan_pitch = std::tan(velocity_pitch_b_rad);
  m.z << v_v.y(), v_v.z() + v_v.x() * tan_pitch;
  m.h.setZero();
  m.h.block<2, 3>(0, kVel.index) = dvv_dv.bottomRows<2>();
  m.h.block<2, 3>(0, kAtt.index) = dvv_dphi.bottomRows<2>();
  m.h.block<1, 3>(1, kVel.index) += tan_pitch * dvv_dv.row(0);
  m.h.block<1, 3>(1, kAtt.index) += tan_pitch * dvv_dphi.row(0);
  if (mounting_rad != nullptr) {
    m.h.block<2, 3>(0, kMountingMisalignment.index) = dvv_dmu.bottomRows<2>();
    m.h.block<1, 3>(1, kMountingMisalignment.index) += tan_pitch * dvv_dmu.row(0);
  }
  m.r = Eigen::Matrix2d::Identity() * sigma_mps * sigma_mps;
  return m;
}

}  // namespace navbus::core
