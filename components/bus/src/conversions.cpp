#include "navbus/bus/conversions.hpp"

#include <algorithm>

#include "navbus/core/math/rotation.hpp"

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
  return toCore(m, {});
}

std::vector<core::SatelliteObservation> toCore(const navbus::GnssObservationEpoch& m,
                                               const std::vector<SatelliteRejection>& dropped) {
  std::vector<core::SatelliteObservation> out;
  toCore(m, dropped, out);
  return out;
}

void toCore(const navbus::GnssObservationEpoch& m, const std::vector<SatelliteRejection>& dropped,
            std::vector<core::SatelliteObservation>& out) {
  out.clear();
  out.reserve(m.satellites().size());
  for (std::size_t i = 0; i < m.satellites().size(); ++i) {
    const auto& s = m.satellites()[i];
    const bool is_dropped = std::any_of(dropped.begin(), dropped.end(),
                                        [i](const SatelliteRejection& d) { return d.index == i; });
    if (!s.valid() || is_dropped) continue;
    out.push_back({s.sv_id(), toVector(s.sat_pos_ecef_m()), toVector(s.sat_vel_ecef_mps()),
                   s.pseudorange_m() + s.sat_clock_correction_m(),
                   s.pseudorange_rate_mps() + s.sat_clock_drift_mps(), s.pseudorange_sigma_m(),
                   s.pseudorange_rate_sigma_mps()});
  }
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

core::NavState toCore(const navbus::NavigationSolution& s) {
  core::NavState n;
  n.time_ns = static_cast<std::int64_t>(s.time_gps_ns());
  n.position = {s.latitude_rad(), s.longitude_rad(), s.height_m()};
  n.vel_ned_mps = toVector(s.vel_ned_mps());
  n.q_b_to_n =
      Eigen::Quaterniond(s.q_b_to_n()[0], s.q_b_to_n()[1], s.q_b_to_n()[2], s.q_b_to_n()[3]);
  return n;
}

namespace {
struct LayoutEntry {
  const char* name;
  core::StateBlock block;
  const char* unit;
};
constexpr LayoutEntry kStateLayout[] = {
    {"pos_ned", core::layout::kPos, "m"},
    {"vel_ned", core::layout::kVel, "m/s"},
    {"phi_ned", core::layout::kAtt, "rad"},
    {"accel_bias", core::layout::kAccelBias, "m/s^2"},
    {"gyro_bias", core::layout::kGyroBias, "rad/s"},
    {"star_tracker_bias", core::layout::kStarTrackerBias, "rad"},
    {"clock_bias", core::layout::kClockBias, "m"},
    {"clock_drift", core::layout::kClockDrift, "m/s"},
    {"pseudorange_error", core::layout::kPseudorangeError, "m"},
    {"clock2_bias", core::layout::kSecondClockBias, "m"},
    {"clock2_drift", core::layout::kSecondClockDrift, "m/s"},
    {"accel_scale", core::layout::kAccelScale, "1"},
    {"gyro_scale", core::layout::kGyroScale, "1"}};
}  // namespace

void fillStateLayout(navbus::FilterDiagnostics& msg) {
  msg.n(static_cast<std::uint16_t>(core::layout::kSize));
  msg.state_layout().clear();
  for (const LayoutEntry& e : kStateLayout) {
    navbus::StateBlock b;
    b.name(e.name);
    b.index(static_cast<std::uint16_t>(e.block.index));
    b.dof(static_cast<std::uint16_t>(e.block.dof));
    b.unit(e.unit);
    msg.state_layout().push_back(b);
  }
}

navbus::FilterDiagnostics toIdl(const core::EpochDiagnostics& d, std::uint32_t vehicle_id,
                                std::uint64_t seq, std::int64_t time_ns,
                                const FusedReceiverIds& receiver_ids) {
  navbus::FilterDiagnostics msg;
  msg.vehicle_id(vehicle_id);
  msg.seq(seq);
  msg.time_gps_ns(static_cast<std::uint64_t>(time_ns));
  const auto m = static_cast<std::uint16_t>(d.h.rows());
  fillStateLayout(msg);
  msg.m(m);
  for (std::size_t r = 0; r < m; ++r) {
    navbus::MeasurementRow row;
    row.kind(d.is_rate[r] ? navbus::MEAS_PSEUDORANGE_RATE : navbus::MEAS_PSEUDORANGE);
    row.sv_id(static_cast<std::uint16_t>(d.sv_ids[r]));
    row.used(d.used[r]);
    const int receiver = r < d.receivers.size() ? d.receivers[r] : 0;
    row.receiver_id(receiver_ids[static_cast<std::size_t>(receiver)]);
    msg.rows().push_back(row);
    msg.innovation().push_back(d.innovation[static_cast<Eigen::Index>(r)]);
    msg.test_ratio().push_back(d.test_ratio[r]);
  }
  auto append = [](const auto& M, auto& out) {
    for (Eigen::Index i = 0; i < M.rows(); ++i)
      for (Eigen::Index j = 0; j < M.cols(); ++j) out.push_back(M(i, j));
  };
  append(d.innovation_cov, msg.innovation_cov());
  append(d.h, msg.h());
  append(d.k, msg.k());
  append(d.phi, msg.phi());
  msg.process_noise_scale(1.0);  // the configured Q, unless the filter's adapts (nav_filter)
  return msg;
}

std::optional<Rejection> toGlrEpoch(const navbus::FilterDiagnostics& msg, core::GlrEpoch& out) {
  constexpr std::size_t n = core::layout::kSize;
  if (msg.n() != n)
    return Rejection{navbus::REJECT_INCONSISTENT, "n", static_cast<double>(msg.n())};
  const auto& layout = msg.state_layout();
  if (layout.size() != std::size(kStateLayout))
    return Rejection{navbus::REJECT_INCONSISTENT, "state_layout.size()",
                     static_cast<double>(layout.size())};
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const LayoutEntry& e = kStateLayout[i];
    if (layout[i].name() != e.name || layout[i].index() != e.block.index ||
        layout[i].dof() != e.block.dof)
      return Rejection{navbus::REJECT_INCONSISTENT, "state_layout[" + std::to_string(i) + "]",
                       static_cast<double>(layout[i].index())};
  }
  const std::size_t m = msg.m();
  if (m > static_cast<std::size_t>(core::glr::kMaxRows))
    return Rejection{navbus::REJECT_OUT_OF_RANGE, "m", static_cast<double>(m)};
  for (std::size_t r = 0; r < m; ++r) {
    const auto kind = msg.rows()[r].kind();
    if (kind != navbus::MEAS_PSEUDORANGE && kind != navbus::MEAS_PSEUDORANGE_RATE)
      return Rejection{navbus::REJECT_INCONSISTENT, "rows[" + std::to_string(r) + "].kind",
                       static_cast<double>(kind)};
  }
  const auto rows = static_cast<Eigen::Index>(m);
  out.time_ns = static_cast<std::int64_t>(msg.time_gps_ns());
  out.rows = static_cast<int>(m);
  out.innovation.resize(rows);
  out.innovation_cov.resize(rows, rows);
  out.h.resize(rows, static_cast<Eigen::Index>(n));
  out.k.resize(static_cast<Eigen::Index>(n), rows);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const auto ur = static_cast<std::size_t>(r);
    out.sv_id[ur] = msg.rows()[ur].sv_id();
    out.is_rate[ur] = msg.rows()[ur].kind() == navbus::MEAS_PSEUDORANGE_RATE;
    out.receiver[ur] = msg.rows()[ur].receiver_id();
    out.innovation[r] = msg.innovation()[ur];
    for (Eigen::Index c = 0; c < rows; ++c)
      out.innovation_cov(r, c) = msg.innovation_cov()[ur * m + static_cast<std::size_t>(c)];
    for (std::size_t j = 0; j < n; ++j) {
      out.h(r, static_cast<Eigen::Index>(j)) = msg.h()[ur * n + j];
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < m; ++c)
      out.k(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = msg.k()[i * m + c];
    for (std::size_t j = 0; j < n; ++j)
      out.phi(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = msg.phi()[i * n + j];
  }
  return std::nullopt;
}

}  // namespace navbus::bus
