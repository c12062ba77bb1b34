#include "navbus/core/gnss/gnss_atmosphere.hpp"

#include <algorithm>
#include <cmath>

#include "navbus/core/gnss/gps_broadcast_ephemeris.hpp"

namespace navbus::core {

AzimuthElevation azimuthElevation(const earth::Geodetic& receiver,
                                  const Eigen::Vector3d& sat_ecef_m) {
  const Eigen::Vector3d los_ecef = (sat_ecef_m - earth::geodeticToEcef(receiver)).normalized();
  const Eigen::Vector3d los_ned =
      earth::C_n_e(receiver.latitude_rad, receiver.longitude_rad).transpose() * los_ecef;
  return {std::atan2(los_ned.y(), los_ned.x()), std::asin(-los_ned.z())};
}

double klobucharDelay_m(const KlobucharParameters& p, const earth::Geodetic& receiver,
                        const AzimuthElevation& direction, double t_s) {
  // IS-GPS-200 Figure 20-4, angles in semicircles.
  const double E = direction.elevation_rad / gps::kPi;
  const double A = direction.azimuth_rad;
  const double phi_u = receiver.latitude_rad / gps::kPi;
  const double lambda_u = receiver.longitude_rad / gps::kPi;
  const double psi = 0.0137 / (E + 0.11) - 0.022;  // Earth-centred angle
  double phi_i = phi_u + psi * std::cos(A);        // sub-ionospheric latitude
  if (phi_i > 0.416) phi_i = 0.416;
  if (phi_i < -0.416) phi_i = -0.416;
  const double lambda_i = lambda_u + psi * std::sin(A) / std::cos(phi_i * gps::kPi);
  const double phi_m = phi_i + 0.064 * std::cos((lambda_i - 1.617) * gps::kPi);  // geomagnetic
  double t_local = std::fmod(4.32e4 * lambda_i + std::fmod(t_s, 86400.0), 86400.0);
  if (t_local < 0.0) t_local += 86400.0;
  const double F = 1.0 + 16.0 * std::pow(0.53 - E, 3);  // obliquity factor
  double amplitude = 0.0, period = 0.0;
  for (int n = 3; n >= 0; --n) {
    amplitude = amplitude * phi_m + p.alpha[static_cast<std::size_t>(n)];
    period = period * phi_m + p.beta[static_cast<std::size_t>(n)];
  }
  if (amplitude < 0.0) amplitude = 0.0;
  if (period < 72000.0) period = 72000.0;
  const double x = 2.0 * gps::kPi * (t_local - 50400.0) / period;  // phase [rad]
  double delay_s = F * 5e-9;
  if (std::abs(x) < 1.57) {
    const double x2 = x * x;
    delay_s += F * amplitude * (1.0 - x2 / 2.0 + x2 * x2 / 24.0);
  }
  return earth::kSpeedOfLight_mps * delay_s;
}

double saastamoinenDelay_m(const earth::Geodetic& receiver, double elevation_rad,
                           double relative_humidity) {
  if (elevation_rad <= 0.0) return 0.0;
  // The standard atmosphere is evaluated between sea level and 10 km. Clamping (rather than
  // returning 0 outside, as some implementations do) keeps the delay continuous in the
  // height: an iterate of a least-squares fix that crosses the cut would otherwise oscillate.
  const double h_m = std::clamp(receiver.height_m, 0.0, 1e4);
  const double pressure_hpa = 1013.25 * std::pow(1.0 - 2.2557e-5 * h_m, 5.2568);
  const double temperature_k = 15.0 - 6.5e-3 * h_m + 273.16;
  const double vapour_hpa = 6.108 * relative_humidity *
                            std::exp((17.15 * temperature_k - 4684.0) / (temperature_k - 38.45));
  const double cos_z = std::cos(M_PI / 2.0 - elevation_rad);
  const double hydrostatic =
      0.0022768 * pressure_hpa /
      (1.0 - 0.00266 * std::cos(2.0 * receiver.latitude_rad) - 0.00028 * h_m / 1e3) / cos_z;
  const double wet = 0.002277 * (1255.0 / temperature_k + 0.05) * vapour_hpa / cos_z;
  return hydrostatic + wet;
}

}  // namespace navbus::core
