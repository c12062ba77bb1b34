#include "navbus/sim/constellation.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "navbus/core/math/earth.hpp"

namespace navbus::sim {

namespace earth = core::earth;

std::vector<KeplerElements> gpsLikeAlmanac(const ConstellationConfig& c) {
  std::vector<KeplerElements> out;
  int sv = 1;
  for (int p = 0; p < c.planes; ++p) {
    for (int s = 0; s < c.satellites_per_plane; ++s) {
      KeplerElements k;
      k.sv_id = sv++;
      k.semi_major_axis_m = c.radius_m;
      k.eccentricity = c.eccentricity;
      k.inclination_rad = c.inclination_rad;
      k.raan_rad = 2.0 * M_PI * p / c.planes;
      // Slots evenly spaced in a plane, phased by plane so that planes do not line up.
      k.mean_anomaly_rad = 2.0 * M_PI * s / c.satellites_per_plane + M_PI * p / (2.0 * c.planes);
      // Satellite clocks: offsets of a few tens of microseconds and drifts of 1e-11, spread
      // over the satellites (typical broadcast af0 / af1 magnitudes), fixed per sv id.
      k.clock_bias_s = 1e-5 * static_cast<double>((k.sv_id * 37) % 11 - 5);
      k.clock_drift_sps = 1e-12 * static_cast<double>((k.sv_id * 13) % 7 - 3);
      out.push_back(k);
    }
  }
  return out;
}

double eccentricAnomaly(double m, double e) {
  double E = e < 0.8 ? m : M_PI;
  for (int i = 0; i < 30; ++i) {
    const double d = (E - e * std::sin(E) - m) / (1.0 - e * std::cos(E));
    E -= d;
    if (std::abs(d) < 1e-15) break;
  }
  return E;
}

Constellation::Constellation(std::vector<KeplerElements> almanac) : almanac_(std::move(almanac)) {
  for (const auto& k : almanac_) {
    if (k.sv_id < 1 || k.sv_id > 32 || k.eccentricity < 0.0 || k.eccentricity >= 1.0 ||
        k.semi_major_axis_m <= 0.0) {
      throw std::invalid_argument("almanac entry for sv " + std::to_string(k.sv_id) +
                                  " is not a valid orbit");
    }
    perifocal_to_eci_.push_back((Eigen::AngleAxisd(k.raan_rad, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(k.inclination_rad, Eigen::Vector3d::UnitX()) *
                                 Eigen::AngleAxisd(k.arg_perigee_rad, Eigen::Vector3d::UnitZ()))
                                    .toRotationMatrix());
  }
}

const KeplerElements& Constellation::elements(int sv_id) const {
  return almanac_[indexOf(sv_id)];
}

std::size_t Constellation::indexOf(int sv_id) const {
  for (std::size_t i = 0; i < almanac_.size(); ++i) {
    if (almanac_[i].sv_id == sv_id) return i;
  }
  throw std::out_of_range("sv " + std::to_string(sv_id) + " is not in the almanac");
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> Constellation::eci(int sv_id, double t) const {
  const std::size_t index = indexOf(sv_id);
  const KeplerElements& k = almanac_[index];
  const double a = k.semi_major_axis_m, e = k.eccentricity;
  const double n = std::sqrt(earth::kGm_m3ps2 / (a * a * a));
  const double E = eccentricAnomaly(k.mean_anomaly_rad + n * (t - k.epoch_gps_s), e);
  const double cE = std::cos(E), sE = std::sin(E);
  const double b = a * std::sqrt(1.0 - e * e);
  // Perifocal position and velocity (two-body motion).
  const Eigen::Vector3d r_pf(a * (cE - e), b * sE, 0.0);
  const double Edot = n / (1.0 - e * cE);
  const Eigen::Vector3d v_pf(-a * sE * Edot, b * cE * Edot, 0.0);
  const Eigen::Matrix3d& C = perifocal_to_eci_[index];
  return {C * r_pf, C * v_pf};
}

double Constellation::clockOffset(int sv_id, double t) const {
  const KeplerElements& k = elements(sv_id);
  return k.clock_bias_s + k.clock_drift_sps * (t - k.epoch_gps_s);
}

double Constellation::clockDrift(int sv_id) const {
  return elements(sv_id).clock_drift_sps;
}

SatelliteState Constellation::state(int sv_id, double t) const {
  const auto [r_i, v_i] = eci(sv_id, t);
  const Eigen::Matrix3d C_i_e = earth::C_i_e(t);
  const Eigen::Vector3d w(0.0, 0.0, earth::kRotationRate_radps);
  SatelliteState s;
  s.sv_id = sv_id;
  s.pos_ecef_m = C_i_e * r_i;
  s.vel_ecef_mps = C_i_e * (v_i - w.cross(r_i));
  return s;
}

}  // namespace navbus::sim
