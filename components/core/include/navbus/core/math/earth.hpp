// WGS84 Earth model: constants, curvature, normal gravity, frame conversions.
// Pure math, SI units, no I/O.
#pragma once

#include <Eigen/Core>

namespace navbus::core::earth {

// WGS84 defining constants (NIMA TR8350.2).
inline constexpr double kSemiMajorAxis_m = 6378137.0;
inline constexpr double kFlattening = 1.0 / 298.257223563;
inline constexpr double kRotationRate_radps = 7.292115e-5;
inline constexpr double kGm_m3ps2 = 3.986004418e14;
// Derived.
inline constexpr double kSemiMinorAxis_m = kSemiMajorAxis_m * (1.0 - kFlattening);
inline constexpr double kEccentricitySq = kFlattening * (2.0 - kFlattening);
// Somigliana normal gravity on the ellipsoid (NIMA TR8350.2 eq. 4-1).
inline constexpr double kGravityEquator_mps2 = 9.7803253359;
inline constexpr double kGravityPole_mps2 = 9.8321849378;
inline constexpr double kSpeedOfLight_mps = 299792458.0;

/// Geodetic position on WGS84.
struct Geodetic {
  double latitude_rad{0.0};
  double longitude_rad{0.0};
  double height_m{0.0};
};

/// Radii of curvature at a latitude: meridian (north-south) and prime vertical (east-west).
struct Radii {
  double meridian_m;
  double prime_vertical_m;
};

Radii radiiOfCurvature(double latitude_rad);

/// Magnitude of normal gravity (gravitation plus centrifugal) at latitude and height,
/// Somigliana on the ellipsoid with the second-order free-air correction (TR8350.2 eq. 4-3).
double normalGravity(double latitude_rad, double height_m);

/// Normal gravity vector in NED (the normal-gravity field is along the ellipsoid normal).
Eigen::Vector3d gravityNed(double latitude_rad, double height_m);

/// Which gravity field a mechanization or a simulation uses. Truth and navigation must agree:
/// seed 001 models a spherical Earth (point-mass gravitation), the others WGS84 normal gravity.
enum class GravityModel {
  kWgs84Normal,  ///< Somigliana with the second-order height correction (surface and aircraft)
  kPointMass     ///< GM / r^2 towards the centre, plus the centrifugal term (orbits, seed 001)
};

/// Gravity (gravitation plus centrifugal) in NED at a position, for the chosen model.
Eigen::Vector3d gravityNed(GravityModel model, const Geodetic& position);

/// Point-mass gravitation (no centrifugal term) in ECEF at an ECEF position.
Eigen::Vector3d pointMassGravitationEcef(const Eigen::Vector3d& pos_ecef_m);

Eigen::Vector3d geodeticToEcef(const Geodetic& position);

/// The position moved by a small offset in NED metres, with the curvature at `p` (first order
/// in the offset: for errors, fix noise and fault pulses, not for trajectories).
Geodetic offsetNed(const Geodetic& p, const Eigen::Vector3d& offset_ned_m);

/// The small difference a - b in NED metres at a (first order; longitude wrapped to +-pi).
Eigen::Vector3d differenceNed(const Geodetic& a, const Geodetic& b);

/// Exact-to-machine-precision inverse (iterated), valid from the centre of the Earth to orbit.
Geodetic ecefToGeodetic(const Eigen::Vector3d& pos_ecef_m);

/// Direction cosine matrix rotating NED vectors into ECEF at the given latitude and longitude.
Eigen::Matrix3d C_n_e(double latitude_rad, double longitude_rad);

/// Earth rate expressed in NED.
Eigen::Vector3d omegaIeNed(double latitude_rad);

/// Transport rate (rotation of NED w.r.t. ECEF) for a velocity w.r.t. Earth in NED.
Eigen::Vector3d omegaEnNed(const Geodetic& position, const Eigen::Vector3d& vel_ned_mps);
/// The same with the radii of curvature at the position's latitude already computed.
Eigen::Vector3d omegaEnNed(const Geodetic& position, const Eigen::Vector3d& vel_ned_mps,
                           const Radii& radii);

/// The Earth at one position and velocity, as the mechanization and the error model both use
/// it at the start of a step: computed once per step.
struct LocalEarth {
  Radii radii;
  Eigen::Vector3d w_ie_ned;  ///< omegaIeNed
  Eigen::Vector3d w_en_ned;  ///< omegaEnNed
  Eigen::Vector3d g_ned;     ///< gravityNed
};
LocalEarth localEarth(GravityModel model, const Geodetic& position,
                      const Eigen::Vector3d& vel_ned_mps);

/// Rotation from ECI (coinciding with ECEF at GPS time 0) into ECEF at GPS time t.
Eigen::Matrix3d C_i_e(double gps_time_s);

}  // namespace navbus::core::earth
