#include "navbus/core/ins/strapdown.hpp"

#include <cmath>

#include "navbus/core/math/rotation.hpp"

namespace navbus::core {

void StrapdownNed::initialize(const NavState& state) {
  state_ = state;
  state_.q_b_to_n.normalize();
  has_previous_ = false;
  initialized_ = true;
}

void StrapdownNed::restartAt(std::int64_t time_ns) {
  state_.time_ns = time_ns;
  has_previous_ = false;
}

void StrapdownNed::propagate(const ImuIncrement& inc, const earth::LocalEarth& at_state) {
  const double dt = inc.interval_s;
  const Eigen::Vector3d& dth = inc.delta_angle_b_rad;
  const Eigen::Vector3d& dv = inc.delta_vel_b_mps;
  const Eigen::Vector3d dth_prev =
      has_previous_ ? previous_.delta_angle_b_rad : Eigen::Vector3d::Zero();
  const Eigen::Vector3d dv_prev =
      has_previous_ ? previous_.delta_vel_b_mps : Eigen::Vector3d::Zero();

  const earth::Geodetic pos0 = state_.position;
  const Eigen::Vector3d vel0 = state_.vel_ned_mps;
  const Eigen::Matrix3d C_b_n0 = state_.q_b_to_n.toRotationMatrix();

  // Rotation and sculling compensation of the velocity increment, body frame at t0
  // (two-sample form, Savage eq. 7.2.2.2-22 with the previous interval as first sample).
  const Eigen::Vector3d dv_sf_b =
      dv + 0.5 * dth.cross(dv) + (dth_prev.cross(dv) + dv_prev.cross(dth)) / 12.0;

  // Mid-interval extrapolation of position and velocity, refined once with the new velocity.
  Eigen::Vector3d vel1 = vel0;
  const earth::Radii& r0 = at_state.radii;
  const double cos_lat0 = std::cos(pos0.latitude_rad);
  earth::Geodetic pos_mid = pos0;
  Eigen::Vector3d vel_mid = vel0;
  for (int pass = 0; pass < 2; ++pass) {
    // The first pass is at the state itself.
    const earth::LocalEarth e =
        pass == 0 ? at_state : earth::localEarth(gravity_, pos_mid, vel_mid);
    const Eigen::Vector3d& w_ie = e.w_ie_ned;
    const Eigen::Vector3d& w_en = e.w_en_ned;
    const Eigen::Vector3d zeta = (w_ie + w_en) * dt;  // NED rotation over the interval
    const Eigen::Vector3d dv_sf_n =
        (Eigen::Matrix3d::Identity() - 0.5 * skew(zeta)) * C_b_n0 * dv_sf_b;
    const Eigen::Vector3d dv_cor_n = (e.g_ned - (2.0 * w_ie + w_en).cross(vel_mid)) * dt;
    vel1 = vel0 + dv_sf_n + dv_cor_n;
    vel_mid = 0.5 * (vel0 + vel1);
    // Position at mid-interval for the next pass (half step with the mid velocity).
    pos_mid.latitude_rad =
        pos0.latitude_rad + 0.5 * dt * vel_mid.x() / (r0.meridian_m + pos0.height_m);
    pos_mid.longitude_rad =
        pos0.longitude_rad +
        0.5 * dt * vel_mid.y() / ((r0.prime_vertical_m + pos0.height_m) * cos_lat0);
    pos_mid.height_m = pos0.height_m - 0.5 * dt * vel_mid.z();
  }

  // Position: trapezoidal velocity with radii at mid-interval.
  const earth::Radii r_mid = earth::radiiOfCurvature(pos_mid.latitude_rad);
  earth::Geodetic pos1;
  pos1.height_m = pos0.height_m - dt * vel_mid.z();
  const double h_mid = 0.5 * (pos0.height_m + pos1.height_m);
  pos1.latitude_rad = pos0.latitude_rad + dt * vel_mid.x() / (r_mid.meridian_m + h_mid);
  const double lat_mid = 0.5 * (pos0.latitude_rad + pos1.latitude_rad);
  pos1.longitude_rad = pos0.longitude_rad +
                       dt * vel_mid.y() / ((r_mid.prime_vertical_m + h_mid) * std::cos(lat_mid));
  pos1.longitude_rad = std::remainder(pos1.longitude_rad, 2.0 * M_PI);

  // Attitude: body rotation with the coning correction, NED rotation at mid-interval.
  const Eigen::Vector3d phi_b = dth + dth_prev.cross(dth) / 12.0;
  earth::Geodetic pos_att = pos_mid;
  pos_att.latitude_rad = lat_mid;
  pos_att.height_m = h_mid;
  const Eigen::Vector3d zeta =
      (earth::omegaIeNed(lat_mid) + earth::omegaEnNed(pos_att, vel_mid)) * dt;
  state_.q_b_to_n =
      (quaternionFromRotationVector(-zeta) * state_.q_b_to_n * quaternionFromRotationVector(phi_b))
          .normalized();
  state_.vel_ned_mps = vel1;
  state_.position = pos1;
  state_.time_ns = inc.time_ns;
  previous_ = inc;
  has_previous_ = true;
}

}  // namespace navbus::core
