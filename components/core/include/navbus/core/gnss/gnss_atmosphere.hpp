// Signal-path corrections for single-frequency GPS pseudoranges: satellite azimuth and
// elevation, the broadcast (Klobuchar) ionosphere model of IS-GPS-200 20.3.3.5.2.5 and the
// Saastamoinen troposphere model with a standard atmosphere. Delays in metres, positive: they
// lengthen the measured pseudorange.
#pragma once

#include <array>

#include <Eigen/Core>

#include "navbus/core/math/earth.hpp"

namespace navbus::core {

struct AzimuthElevation {
  double azimuth_rad{0.0};    ///< from north, clockwise (east positive)
  double elevation_rad{0.0};  ///< above the local horizon (ellipsoid normal)
};

/// Direction of `sat_ecef_m` seen from `receiver` (WGS84 geodetic).
AzimuthElevation azimuthElevation(const earth::Geodetic& receiver,
                                  const Eigen::Vector3d& sat_ecef_m);

/// The eight broadcast ionosphere coefficients (subframe 4 page 18; RINEX "ION ALPHA/BETA"),
/// in the message's units: alpha_n [s / semicircle^n], beta_n [s / semicircle^n].
struct KlobucharParameters {
  std::array<double, 4> alpha{};
  std::array<double, 4> beta{};
};

/// L1 ionospheric delay [m] of the broadcast model at GPS time t [s since the GPS epoch].
double klobucharDelay_m(const KlobucharParameters& p, const earth::Geodetic& receiver,
                        const AzimuthElevation& direction, double t_s);

/// Tropospheric delay [m], Saastamoinen's zenith hydrostatic and wet delays of a standard
/// atmosphere (1013.25 hPa and 15 deg C at sea level, -6.5 K/km) with the given relative
/// humidity, mapped with 1/cos(zenith angle). 0 below the horizon or outside -100 m..10 km.
double saastamoinenDelay_m(const earth::Geodetic& receiver, double elevation_rad,
                           double relative_humidity);

}  // namespace navbus::core
