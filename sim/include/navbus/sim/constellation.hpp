// A GPS-like constellation of circular orbits (Walker-type), propagated analytically.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace navbus::sim {

struct SatelliteState {
  int sv_id{0};
  Eigen::Vector3d pos_ecef_m{Eigen::Vector3d::Zero()};
  Eigen::Vector3d vel_ecef_mps{Eigen::Vector3d::Zero()};
};

struct ConstellationConfig {
  int planes{6};
  int satellites_per_plane{4};
  double radius_m{26'559'700.0};  ///< GPS semi-major axis
  double inclination_rad{55.0 * M_PI / 180.0};
};

/// Satellites on circular Keplerian orbits in the ECI frame of Common.idl, rotated into ECEF.
class CircularConstellation {
 public:
  explicit CircularConstellation(const ConstellationConfig& config);
  /// States of every satellite at GPS time t [s].
  std::vector<SatelliteState> states(double gps_time_s) const;
  /// State of one satellite (sv_id 1..N) at GPS time t [s].
  SatelliteState state(int sv_id, double gps_time_s) const;
  int size() const { return config_.planes * config_.satellites_per_plane; }

 private:
  ConstellationConfig config_;
  double mean_motion_radps_;
};

}  // namespace navbus::sim
