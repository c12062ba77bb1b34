// A GNSS constellation propagated from Keplerian, almanac-like elements (two-body motion in the
// ECI frame of Common.idl), rotated into ECEF.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace navbus::sim {

struct SatelliteState {
  int sv_id{0};
  Eigen::Vector3d pos_ecef_m{Eigen::Vector3d::Zero()};
  Eigen::Vector3d vel_ecef_mps{Eigen::Vector3d::Zero()};  ///< relative to the rotating ECEF frame
};

/// Almanac-like Keplerian elements of one satellite.
struct KeplerElements {
  int sv_id{0};
  double semi_major_axis_m{26'559'700.0};
  double eccentricity{0.0};
  double inclination_rad{55.0 * M_PI / 180.0};
  double raan_rad{0.0};  ///< right ascension of the ascending node at the epoch (ECI)
  double arg_perigee_rad{0.0};
  double mean_anomaly_rad{0.0};  ///< at the epoch
  double epoch_gps_s{0.0};
  double clock_bias_s{0.0};     ///< satellite clock offset at the epoch (almanac af0)
  double clock_drift_sps{0.0};  ///< satellite clock drift (almanac af1)
};

/// A GPS-like Walker constellation: `planes` planes 60 deg apart, evenly spaced slots phased
/// from plane to plane, all with the same semi-major axis, eccentricity and inclination.
struct ConstellationConfig {
  int planes{6};
  int satellites_per_plane{4};
  double radius_m{26'559'700.0};  ///< semi-major axis (GPS)
  double eccentricity{0.0};
  double inclination_rad{55.0 * M_PI / 180.0};
};

std::vector<KeplerElements> gpsLikeAlmanac(const ConstellationConfig& config);

/// Solves Kepler's equation E - e sin E = M (Newton, to 1e-15).
double eccentricAnomaly(double mean_anomaly_rad, double eccentricity);

class Constellation {
 public:
  explicit Constellation(std::vector<KeplerElements> almanac);
  explicit Constellation(const ConstellationConfig& config)
      : Constellation(gpsLikeAlmanac(config)) {}
  /// State of satellite sv_id (an id of the almanac) at GPS time t [s].
  SatelliteState state(int sv_id, double gps_time_s) const;
  /// Satellite clock offset [s] at GPS time t (af0 + af1 (t - epoch)).
  double clockOffset(int sv_id, double gps_time_s) const;
  double clockDrift(int sv_id) const;
  /// Inertial (ECI) position and velocity of one satellite.
  std::pair<Eigen::Vector3d, Eigen::Vector3d> eci(int sv_id, double gps_time_s) const;
  const std::vector<KeplerElements>& almanac() const { return almanac_; }
  int size() const { return static_cast<int>(almanac_.size()); }

 private:
  const KeplerElements& elements(int sv_id) const;
  std::size_t indexOf(int sv_id) const;
  std::vector<KeplerElements> almanac_;
  /// Per almanac entry: perifocal -> ECI, R3(raan) R1(i) R3(omega); fixed for two-body orbits.
  std::vector<Eigen::Matrix3d> perifocal_to_eci_;
};

}  // namespace navbus::sim
