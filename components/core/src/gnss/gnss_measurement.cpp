#include "navbus/core/gnss/gnss_measurement.hpp"

#include "navbus/core/math/rotation.hpp"

namespace navbus::core {

RangePrediction predictRange(const NavState& ins, double clock_bias_m, double clock_drift_mps,
                             const SatelliteObservation& sat, const AntennaArm& antenna) {
  using namespace layout;
  const Eigen::Matrix3d C_n_e = earth::C_n_e(ins.position.latitude_rad, ins.position.longitude_rad);
  const Eigen::Vector3d arm_ned_m = ins.q_b_to_n * antenna.lever_arm_b_m;
  const Eigen::Vector3d arm_vel_ned_mps =
      ins.q_b_to_n * antenna.rate_nb_b_radps.cross(antenna.lever_arm_b_m);
  const Eigen::Vector3d r = earth::geodeticToEcef(ins.position) + C_n_e * arm_ned_m;
  const Eigen::Vector3d v_e = C_n_e * (ins.vel_ned_mps + arm_vel_ned_mps);
  const Eigen::Vector3d d = sat.sat_pos_ecef_m - r;
  const double range = d.norm();
  const Eigen::Vector3d los_e = d / range;
  RangePrediction p;
  p.pseudorange_m = range + clock_bias_m;
  p.pseudorange_rate_mps = los_e.dot(sat.sat_vel_ecef_mps - v_e) + clock_drift_mps;
  p.los_ned = C_n_e.transpose() * los_e;
  p.h_range.setZero();
  p.h_rate.setZero();
  // A position error along the line of sight shortens the predicted range.
  p.h_range.block<1, 3>(0, kPos.index) = -p.los_ned.transpose();
  // A tilt error moves the estimated antenna about the IMU by -phi x a = [a x] phi.
  p.h_range.block<1, 3>(0, kAtt.index) = -p.los_ned.transpose() * skew(arm_ned_m);
  p.h_range(0, clockBiasOf(sat.receiver).index) = 1.0;
  p.h_rate.block<1, 3>(0, kVel.index) = -p.los_ned.transpose();
  p.h_rate.block<1, 3>(0, kAtt.index) = -p.los_ned.transpose() * skew(arm_vel_ned_mps);
  p.h_rate(0, clockDriftOf(sat.receiver).index) = 1.0;
  return p;
}

}  // namespace navbus::core
