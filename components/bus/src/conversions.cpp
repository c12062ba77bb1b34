#include "navbus/bus/conversions.hpp"

#include "navbus/core/rotation.hpp"

namespace navbus::bus {

core::ImuIncrement toCore(const navbus::ImuIncrement& msg) {
  core::ImuIncrement inc;
  inc.time_ns = static_cast<std::int64_t>(msg.time_gps_ns());
  inc.interval_s = 1e-9 * static_cast<double>(msg.interval_ns());
  inc.delta_vel_b_mps = toVector(msg.delta_vel_b_mps());
  inc.delta_angle_b_rad = toVector(msg.delta_angle_b_rad());
  return inc;
}

navbus::ImuIncrement toIdl(const core::ImuIncrement& inc, std::uint32_t sensor_id,
                           std::uint64_t seq) {
  navbus::ImuIncrement msg;
  msg.sensor_id(sensor_id);
  msg.seq(seq);
  msg.time_gps_ns(static_cast<std::uint64_t>(inc.time_ns));
  msg.interval_ns(static_cast<std::uint32_t>(std::llround(inc.interval_s * 1e9)));
  msg.delta_vel_b_mps(toArray(inc.delta_vel_b_mps));
  msg.delta_angle_b_rad(toArray(inc.delta_angle_b_rad));
  msg.status_flags(0);
  return msg;
}

void fillSolution(const core::NavState& s, navbus::NavigationSolution& out) {
  out.time_gps_ns(static_cast<std::uint64_t>(s.time_ns));
  out.latitude_rad(s.position.latitude_rad);
  out.longitude_rad(s.position.longitude_rad);
  out.height_m(s.position.height_m);
  const Eigen::Vector3d ecef = core::earth::geodeticToEcef(s.position);
  const Eigen::Vector3d rpy = core::eulerFromDcm(s.q_b_to_n.toRotationMatrix());
  out.pos_ecef_m(toArray(ecef));
  out.vel_ned_mps(toArray(s.vel_ned_mps));
  out.q_b_to_n() = {s.q_b_to_n.w(), s.q_b_to_n.x(), s.q_b_to_n.y(), s.q_b_to_n.z()};
  out.roll_rad(rpy.x());
  out.pitch_rad(rpy.y());
  out.yaw_rad(rpy.z());
}

}  // namespace navbus::bus
