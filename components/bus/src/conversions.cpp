#include "navbus/bus/conversions.hpp"

#include "navbus/core/rotation.hpp"

namespace navbus::bus {

core::ImuIncrement toCore(const navbus::ImuIncrement& msg) {
  core::ImuIncrement inc;
  inc.time_ns = static_cast<std::int64_t>(msg.time_gps_ns());
  inc.interval_s = 1e-9 * static_cast<double>(msg.interval_ns());
  for (int i = 0; i < 3; ++i) {
    inc.delta_vel_b_mps[i] = msg.delta_vel_b_mps()[static_cast<std::size_t>(i)];
    inc.delta_angle_b_rad[i] = msg.delta_angle_b_rad()[static_cast<std::size_t>(i)];
  }
  return inc;
}

navbus::ImuIncrement toIdl(const core::ImuIncrement& inc, std::uint32_t sensor_id,
                           std::uint64_t seq) {
  navbus::ImuIncrement msg;
  msg.sensor_id(sensor_id);
  msg.seq(seq);
  msg.time_gps_ns(static_cast<std::uint64_t>(inc.time_ns));
  msg.interval_ns(static_cast<std::uint32_t>(std::llround(inc.interval_s * 1e9)));
  for (int i = 0; i < 3; ++i) {
    msg.delta_vel_b_mps()[static_cast<std::size_t>(i)] = inc.delta_vel_b_mps[i];
    msg.delta_angle_b_rad()[static_cast<std::size_t>(i)] = inc.delta_angle_b_rad[i];
  }
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
  for (std::size_t i = 0; i < 3; ++i) {
    out.pos_ecef_m()[i] = ecef[static_cast<int>(i)];
    out.vel_ned_mps()[i] = s.vel_ned_mps[static_cast<int>(i)];
  }
  out.q_b_to_n() = {s.q_b_to_n.w(), s.q_b_to_n.x(), s.q_b_to_n.y(), s.q_b_to_n.z()};
  out.roll_rad(rpy.x());
  out.pitch_rad(rpy.y());
  out.yaw_rad(rpy.z());
}

}  // namespace navbus::bus
