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

core::GnssFixMeasurement toCore(const navbus::GnssFix& msg) {
  core::GnssFixMeasurement f;
  f.time_ns = static_cast<std::int64_t>(msg.time_gps_ns());
  f.position = {msg.latitude_rad(), msg.longitude_rad(), msg.height_m()};
  f.vel_ned_mps = toVector(msg.vel_ned_mps());
  f.pos_sigma_ned_m = toVector(msg.pos_sigma_ned_m());
  f.vel_sigma_ned_mps = toVector(msg.vel_sigma_ned_mps());
  return f;
}

core::StarAttitudeMeasurement toCore(const navbus::StarTrackerAttitude& msg) {
  core::StarAttitudeMeasurement st;
  st.time_ns = static_cast<std::int64_t>(msg.time_gps_ns());
  const auto& q = msg.q_b_to_i();
  st.q_b_to_i = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
  st.sigma_b_rad = toVector(msg.sigma_b_rad());
  return st;
}

std::vector<core::SatelliteObservation> toCore(const navbus::GnssObservationEpoch& m) {
  std::vector<core::SatelliteObservation> out;
  out.reserve(m.satellites().size());
  for (const auto& s : m.satellites()) {
    if (!s.valid()) continue;
    out.push_back({s.sv_id(), toVector(s.sat_pos_ecef_m()), toVector(s.sat_vel_ecef_mps()),
                   s.pseudorange_m() + s.sat_clock_correction_m(),
                   s.pseudorange_rate_mps() + s.sat_clock_drift_mps(), s.pseudorange_sigma_m(),
                   s.pseudorange_rate_sigma_mps()});
  }
  return out;
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
