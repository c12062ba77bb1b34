#include "navbus/sim/constellation.hpp"

#include <cmath>

#include "navbus/core/earth.hpp"
#include "navbus/core/rotation.hpp"

namespace navbus::sim {

namespace earth = core::earth;

CircularConstellation::CircularConstellation(const ConstellationConfig& config)
    : config_(config),
      mean_motion_radps_(std::sqrt(earth::kGm_m3ps2 / std::pow(config.radius_m, 3))) {}

SatelliteState CircularConstellation::state(int sv_id, double t) const {
  const int index = sv_id - 1;
  const int plane = index / config_.satellites_per_plane;
  const int slot = index % config_.satellites_per_plane;
  const double raan = 2.0 * M_PI * plane / config_.planes;
  // Slots evenly spaced in a plane, phased by plane so that planes do not line up.
  const double u0 =
      2.0 * M_PI * slot / config_.satellites_per_plane + M_PI * plane / (2.0 * config_.planes);
  const double u = u0 + mean_motion_radps_ * t;
  const double r = config_.radius_m;
  const Eigen::Vector3d pos_orbit(r * std::cos(u), r * std::sin(u), 0.0);
  const Eigen::Vector3d vel_orbit(-r * mean_motion_radps_ * std::sin(u),
                                  r * mean_motion_radps_ * std::cos(u), 0.0);
  const Eigen::Matrix3d C_orbit_i =
      (Eigen::AngleAxisd(raan, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(config_.inclination_rad, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Vector3d pos_i = C_orbit_i * pos_orbit;
  const Eigen::Vector3d vel_i = C_orbit_i * vel_orbit;
  const Eigen::Matrix3d C_i_e = earth::C_i_e(t);
  const Eigen::Vector3d omega_ie_i(0.0, 0.0, earth::kRotationRate_radps);
  SatelliteState s;
  s.sv_id = sv_id;
  s.pos_ecef_m = C_i_e * pos_i;
  // Velocity relative to the rotating ECEF frame.
  s.vel_ecef_mps = C_i_e * (vel_i - omega_ie_i.cross(pos_i));
  return s;
}

std::vector<SatelliteState> CircularConstellation::states(double t) const {
  std::vector<SatelliteState> out;
  out.reserve(static_cast<std::size_t>(size()));
  for (int sv = 1; sv <= size(); ++sv) {
    out.push_back(state(sv, t));
  }
  return out;
}

}  // namespace navbus::sim
