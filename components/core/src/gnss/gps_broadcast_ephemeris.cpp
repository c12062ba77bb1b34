#include "navbus/core/gnss/gps_broadcast_ephemeris.hpp"

#include <cmath>

namespace navbus::core::gps {

namespace {

/// Kepler's equation M = E - e sin E by Newton iteration (to 1e-14 rad).
double eccentricAnomaly(double mean_anomaly_rad, double e) {
  double E = mean_anomaly_rad;
  for (int i = 0; i < 30; ++i) {
    const double step = (E - e * std::sin(E) - mean_anomaly_rad) / (1.0 - e * std::cos(E));
    E -= step;
    if (std::abs(step) < 1e-14) break;
  }
  return E;
}

struct Orbit {
  Eigen::Vector3d pos_ecef_m;
  double eccentric_anomaly_rad;
};

/// IS-GPS-200 Table 20-IV, term by term.
Orbit orbitAt(const BroadcastEphemeris& eph, double t_s) {
  const double A = eph.sqrt_a_sqrtm * eph.sqrt_a_sqrtm;  // semi-major axis
  const double n0 = std::sqrt(kGm_m3ps2 / (A * A * A));  // computed mean motion
  const double tk = t_s - eph.toe_s;                     // time from ephemeris epoch
  const double n = n0 + eph.delta_n_radps;               // corrected mean motion
  const double Mk = eph.m0_rad + n * tk;                 // mean anomaly
  const double e = eph.eccentricity;
  const double Ek = eccentricAnomaly(Mk, e);  // Kepler's equation
  const double vk = std::atan2(std::sqrt(1.0 - e * e) * std::sin(Ek), std::cos(Ek) - e);
  const double phik = vk + eph.argument_of_perigee_rad;  // argument of latitude
  const double s2 = std::sin(2.0 * phik), c2 = std::cos(2.0 * phik);
  const double uk = phik + eph.cus_rad * s2 + eph.cuc_rad * c2;                      // corrected u
  const double rk = A * (1.0 - e * std::cos(Ek)) + eph.crs_m * s2 + eph.crc_m * c2;  // radius
  const double ik = eph.i0_rad + eph.idot_radps * tk + eph.cis_rad * s2 + eph.cic_rad * c2;
  const double xp = rk * std::cos(uk), yp = rk * std::sin(uk);  // position in orbital plane
  // Corrected longitude of ascending node (from the week's start: toe as seconds of week).
  const double toe_sow = std::fmod(eph.toe_s, kSecondsPerWeek);
  const double Ok =
      eph.omega0_rad + (eph.omega_dot_radps - kEarthRate_radps) * tk - kEarthRate_radps * toe_sow;
  const double cO = std::cos(Ok), sO = std::sin(Ok), ci = std::cos(ik), si = std::sin(ik);
  return {Eigen::Vector3d(xp * cO - yp * ci * sO, xp * sO + yp * ci * cO, yp * si), Ek};
}

}  // namespace

double satelliteClockOffset(const BroadcastEphemeris& eph, double t_s) {
  const double dt = t_s - eph.toc_s;
  const double E = orbitAt(eph, t_s).eccentric_anomaly_rad;
  const double relativistic =
      kRelativisticF_spsqrtm * eph.eccentricity * eph.sqrt_a_sqrtm * std::sin(E);
  return eph.af0_s + eph.af1_sps * dt + eph.af2_sps2 * dt * dt + relativistic - eph.tgd_s;
}

SatelliteState satelliteState(const BroadcastEphemeris& eph, double t_s) {
  constexpr double kHalfStep_s = 1e-3;
  SatelliteState s;
  s.pos_ecef_m = orbitAt(eph, t_s).pos_ecef_m;
  s.vel_ecef_mps =
      (orbitAt(eph, t_s + kHalfStep_s).pos_ecef_m - orbitAt(eph, t_s - kHalfStep_s).pos_ecef_m) /
      (2.0 * kHalfStep_s);
  s.clock_offset_s = satelliteClockOffset(eph, t_s);
  s.clock_drift_sps = eph.af1_sps + 2.0 * eph.af2_sps2 * (t_s - eph.toc_s);
  return s;
}

const BroadcastEphemeris* selectEphemeris(const std::vector<BroadcastEphemeris>& set, int sv_id,
                                          double t_s) {
  const BroadcastEphemeris* best = nullptr;
  for (const BroadcastEphemeris& eph : set) {
    if (eph.sv_id != sv_id || eph.health != 0) continue;
    const double age = std::abs(t_s - eph.toe_s);
    if (age > kMaxEphemerisAge_s) continue;
    if (best == nullptr || age < std::abs(t_s - best->toe_s)) best = &eph;
  }
  return best;
}

}  // namespace navbus::core::gps
