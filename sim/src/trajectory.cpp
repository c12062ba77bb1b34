#include "navbus/sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "navbus/core/math/rotation.hpp"

namespace navbus::sim {

namespace earth = core::earth;

namespace {
// State layout of VehicleTrajectory.
struct Idx {
  static constexpr int lat = 0, lon = 1, h = 2, speed = 3, track = 4, path = 5;
  static constexpr int roll = 6, pitch = 7, yaw = 8, dtheta = 9, dv = 12;
};
static_assert(Idx::dv + 3 == 15, "state layout must fill the vector");

struct Kinematics {
  Eigen::Vector3d vel_n, acc_n, w_nb_b;
  Eigen::Matrix3d C_b_n;
};

Kinematics kinematics(const VehicleTrajectory::Vector& x, const Segment& c) {
  Kinematics k;
  const double cg = std::cos(x[Idx::path]), sg = std::sin(x[Idx::path]);
  const double cp = std::cos(x[Idx::track]), sp = std::sin(x[Idx::track]);
  const Eigen::Vector3d u(cg * cp, cg * sp, -sg);
  const Eigen::Vector3d du_dtrack(-cg * sp, cg * cp, 0.0);
  const Eigen::Vector3d du_dpath(-sg * cp, -sg * sp, -cg);
  const double v = x[Idx::speed];
  k.vel_n = v * u;
  k.acc_n =
      c.accel_mps2 * u + v * (c.heading_rate_radps * du_dtrack + c.climb_rate_radps * du_dpath);
  const double phi = x[Idx::roll], theta = x[Idx::pitch];
  k.C_b_n = core::dcmFromEuler(Eigen::Vector3d(phi, theta, x[Idx::yaw]));
  // Body rate w.r.t. NED from the 3-2-1 Euler angle rates.
  k.w_nb_b = Eigen::Vector3d(
      c.roll_rate_radps - c.yaw_rate_radps * std::sin(theta),
      c.pitch_rate_radps * std::cos(phi) + c.yaw_rate_radps * std::sin(phi) * std::cos(theta),
      -c.pitch_rate_radps * std::sin(phi) + c.yaw_rate_radps * std::cos(phi) * std::cos(theta));
  return k;
}

earth::Geodetic geodetic(const VehicleTrajectory::Vector& x) {
  return {x[Idx::lat], x[Idx::lon], x[Idx::h]};
}
}  // namespace

VehicleTrajectory::VehicleTrajectory(const VehicleStart& start, std::vector<Segment> segments,
                                     earth::GravityModel gravity, double max_step_s)
    : segments_(std::move(segments)), gravity_(gravity), max_step_s_(max_step_s) {
  x_.setZero();
  x_[Idx::lat] = start.position.latitude_rad;
  x_[Idx::lon] = start.position.longitude_rad;
  x_[Idx::h] = start.position.height_m;
  x_[Idx::speed] = start.speed_mps;
  x_[Idx::track] = start.heading_rad;
  x_[Idx::path] = start.flight_path_rad;
  x_[Idx::roll] = start.roll_pitch_yaw_rad.x();
  x_[Idx::pitch] = start.roll_pitch_yaw_rad.y();
  x_[Idx::yaw] = start.roll_pitch_yaw_rad.z();
}

double VehicleTrajectory::duration() const {
  double d = 0.0;
  for (const auto& s : segments_) d += s.duration_s;
  return d;
}

const Segment& VehicleTrajectory::segmentAt(double t) const {
  double end = 0.0;
  for (const auto& s : segments_) {
    end += s.duration_s;
    if (t < end - 1e-9) return s;
  }
  return idle_;
}

double VehicleTrajectory::segmentEnd(double t) const {
  double end = 0.0;
  for (const auto& s : segments_) {
    end += s.duration_s;
    if (t < end - 1e-9) return end;
  }
  return std::numeric_limits<double>::infinity();
}

VehicleTrajectory::Vector VehicleTrajectory::derivative(const Vector& x, const Segment& c) const {
  const Kinematics k = kinematics(x, c);
  const earth::Geodetic p = geodetic(x);
  const earth::Radii r = earth::radiiOfCurvature(p.latitude_rad);
  const Eigen::Vector3d w_ie = earth::omegaIeNed(p.latitude_rad);
  const Eigen::Vector3d w_en = earth::omegaEnNed(p, k.vel_n);
  // Specific force: what the accelerometers feel (Savage's navigation equation solved for f).
  const Eigen::Vector3d f_n =
      k.acc_n + (2.0 * w_ie + w_en).cross(k.vel_n) - earth::gravityNed(gravity_, p);
  const Eigen::Matrix3d C_n_b = k.C_b_n.transpose();
  Vector d;
  d[Idx::lat] = k.vel_n.x() / (r.meridian_m + p.height_m);
  d[Idx::lon] = k.vel_n.y() / ((r.prime_vertical_m + p.height_m) * std::cos(p.latitude_rad));
  d[Idx::h] = -k.vel_n.z();
  d[Idx::speed] = c.accel_mps2;
  d[Idx::track] = c.heading_rate_radps;
  d[Idx::path] = c.climb_rate_radps;
  d[Idx::roll] = c.roll_rate_radps;
  d[Idx::pitch] = c.pitch_rate_radps;
  d[Idx::yaw] = c.yaw_rate_radps;
  d.segment<3>(Idx::dtheta) = k.w_nb_b + C_n_b * (w_ie + w_en);
  d.segment<3>(Idx::dv) = C_n_b * f_n;
  return d;
}

void VehicleTrajectory::rk4(double h, const Segment& c) {
  const Vector k1 = derivative(x_, c);
  const Vector k2 = derivative(x_ + 0.5 * h * k1, c);
  const Vector k3 = derivative(x_ + 0.5 * h * k2, c);
  const Vector k4 = derivative(x_ + h * k3, c);
  x_ += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

PerfectIncrement VehicleTrajectory::advance(double dt_s) {
  x_.segment<6>(Idx::dtheta).setZero();
  const double t_end = t_ + dt_s;
  while (t_ < t_end - 1e-12) {
    // Never step across a command change: RK4 needs smooth derivatives within a step.
    const double stop = std::min(t_end, segmentEnd(t_));
    const int n = std::max(1, static_cast<int>(std::ceil((stop - t_) / max_step_s_ - 1e-9)));
    const double h = (stop - t_) / n;
    const Segment& c = segmentAt(t_);
    for (int i = 0; i < n; ++i) rk4(h, c);
    t_ = stop;
  }
  t_ = t_end;
  return {x_.segment<3>(Idx::dtheta), x_.segment<3>(Idx::dv)};
}

core::NavState VehicleTrajectory::state() const {
  const Kinematics k = kinematics(x_, segmentAt(t_));
  core::NavState s;
  s.position = geodetic(x_);
  s.vel_ned_mps = k.vel_n;
  s.q_b_to_n = Eigen::Quaterniond(k.C_b_n);
  return s;
}

Eigen::Vector3d VehicleTrajectory::specificForceBody() const {
  const Vector d = derivative(x_, segmentAt(t_));
  // The dv integral's derivative is the specific force in the body frame.
  return d.segment<3>(Idx::dv);
}

// ---------------------------------------------------------------------------------------------

CircularOrbitTrajectory::CircularOrbitTrajectory(const OrbitStart& s) : start_(s) {
  if (std::abs(s.latitude_rad) > s.inclination_rad + 1e-12) {
    throw std::invalid_argument("orbit start latitude exceeds the inclination");
  }
  radius_m_ = earth::kSemiMajorAxis_m + s.altitude_m;
  n_ = std::sqrt(earth::kGm_m3ps2 / (radius_m_ * radius_m_ * radius_m_));
  // Ascending pass through the start latitude: sin(lat) = sin(i) sin(u).
  u0_ = std::asin(std::clamp(std::sin(s.latitude_rad) / std::sin(s.inclination_rad), -1.0, 1.0));
  const double ra_offset = std::atan2(std::cos(s.inclination_rad) * std::sin(u0_), std::cos(u0_));
  // Right ascension of the start = start longitude + Earth rotation angle at the start time.
  raan_ = s.longitude_rad + earth::kRotationRate_radps * s.start_gps_s - ra_offset;
  C_orbit_i_ = (Eigen::AngleAxisd(raan_, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(start_.inclination_rad, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
}

Eigen::Vector3d CircularOrbitTrajectory::positionEci() const {
  const double u = u0_ + n_ * t_;
  const Eigen::Vector3d p_orbit(radius_m_ * std::cos(u), radius_m_ * std::sin(u), 0.0);
  return C_orbit_i_ * p_orbit;
}

Eigen::Vector3d CircularOrbitTrajectory::velocityEci() const {
  const double u = u0_ + n_ * t_;
  const Eigen::Vector3d v_orbit(-radius_m_ * n_ * std::sin(u), radius_m_ * n_ * std::cos(u), 0.0);
  return C_orbit_i_ * v_orbit;
}

core::NavState CircularOrbitTrajectory::state() const {
  const double gps_s = start_.start_gps_s + t_;
  const Eigen::Matrix3d C_i_e = earth::C_i_e(gps_s);
  const Eigen::Vector3d r_i = positionEci();
  const Eigen::Vector3d v_i = velocityEci();
  const Eigen::Vector3d r_e = C_i_e * r_i;
  const Eigen::Vector3d w(0.0, 0.0, earth::kRotationRate_radps);
  const Eigen::Vector3d v_e = C_i_e * v_i - w.cross(r_e);
  core::NavState s;
  s.position = earth::ecefToGeodetic(r_e);
  const Eigen::Matrix3d C_n_e = earth::C_n_e(s.position.latitude_rad, s.position.longitude_rad);
  s.vel_ned_mps = C_n_e.transpose() * v_e;
  // LVLH body axes in ECI: x along track, z to nadir, y completing (= minus the orbit normal).
  Eigen::Matrix3d C_b_i;
  C_b_i.col(0) = v_i.normalized();
  C_b_i.col(2) = -r_i.normalized();
  C_b_i.col(1) = C_b_i.col(2).cross(C_b_i.col(0));
  s.q_b_to_n = Eigen::Quaterniond(C_n_e.transpose() * C_i_e * C_b_i);
  return s;
}

PerfectIncrement CircularOrbitTrajectory::advance(double dt_s) {
  t_ += dt_s;
  PerfectIncrement inc;
  inc.delta_angle_b_rad = Eigen::Vector3d(0.0, -n_ * dt_s, 0.0);
  return inc;  // free fall: no specific force
}

}  // namespace navbus::sim
