#include "navbus/sim/gnss_receiver.hpp"

#include <algorithm>
#include <cmath>

#include "navbus/core/gnss/gnss_fix.hpp"
#include "navbus/core/math/earth.hpp"

namespace navbus::sim {

namespace earth = core::earth;

GnssReceiverModel::GnssReceiverModel(const GnssReceiverConfig& config,
                                     const Constellation& constellation)
    : config_(config),
      constellation_(constellation),
      clock_bias_m_(config.clock_bias_m),
      clock_drift_mps_(config.clock_drift_mps) {}

GnssEpoch GnssReceiverModel::observe(std::int64_t t_ns, std::int64_t t0_ns,
                                     const Eigen::Vector3d& rx_pos, const Eigen::Vector3d& rx_vel,
                                     std::mt19937_64& rng) {
  std::normal_distribution<double> unit(0.0, 1.0);
  const double t = 1e-9 * static_cast<double>(t_ns);
  const double since_start_s = 1e-9 * static_cast<double>(t_ns - t0_ns);
  const earth::Geodetic rx_geo = earth::ecefToGeodetic(rx_pos);
  const Eigen::Matrix3d C_e_n = earth::C_n_e(rx_geo.latitude_rad, rx_geo.longitude_rad).transpose();
  // Clock random walk (seed 000 eq. 3) integrated exactly from the previous epoch.
  const double dt = since_start_s - clock_time_s_;
  if (dt > 0.0) {
    const double w2 = config_.clock_drift_noise_mps_per_sqrts * std::sqrt(dt) * unit(rng);
    const double w1 = config_.clock_bias_noise_m_per_sqrts * std::sqrt(dt) * unit(rng);
    clock_bias_m_ += clock_drift_mps_ * dt + w1;
    clock_drift_mps_ += w2;
    clock_time_s_ = since_start_s;
  }
  const double clock_bias = clock_bias_m_;

  GnssEpoch epoch;
  epoch.time_ns = t_ns;
  for (const auto& elements : constellation_.almanac()) {
    const int sv = elements.sv_id;
    if (!tracked_.empty() && std::find(tracked_.begin(), tracked_.end(), sv) == tracked_.end())
      continue;
    // Light-time iteration: the signal left the satellite tau seconds before reception.
    double tau = 0.07;
    SatelliteState s;
    Eigen::Vector3d pos_rot;
    Eigen::Vector3d vel_rot;
    for (int it = 0; it < 4; ++it) {
      s = constellation_.state(sv, t - tau);
      // Sagnac: express the transmit-time position in the ECEF frame of reception time.
      const double a = earth::kRotationRate_radps * tau;
      const Eigen::Matrix3d rot =
          Eigen::AngleAxisd(-a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      pos_rot = rot * s.pos_ecef_m;
      vel_rot = rot * s.vel_ecef_mps;
      tau = (pos_rot - rx_pos).norm() / earth::kSpeedOfLight_mps;
    }
    const Eigen::Vector3d los = (pos_rot - rx_pos).normalized();
    const Eigen::Vector3d los_n = C_e_n * los;
    const double elevation = std::asin(-los_n.z());
    if (elevation < config_.elevation_mask_rad) {
      continue;
    }
    SatelliteMeasurement m;
    m.sv_id = sv;
    m.elevation_rad = elevation;
    m.sat_pos_ecef_m = pos_rot;
    m.sat_vel_ecef_mps = vel_rot;
    // The satellite clock runs ahead by dt_sv: the measured range is shortened by c dt_sv, and
    // the message carries the correction (corrected = measured + c dt_sv).
    m.sat_clock_correction_m = earth::kSpeedOfLight_mps * constellation_.clockOffset(sv, t - tau);
    m.sat_clock_drift_mps = earth::kSpeedOfLight_mps * constellation_.clockDrift(sv);
    m.pseudorange_m = (pos_rot - rx_pos).norm() + clock_bias - m.sat_clock_correction_m +
                      config_.pseudorange_sigma_m * unit(rng);
    m.pseudorange_rate_mps = los.dot(vel_rot - rx_vel) + clock_drift_mps_ - m.sat_clock_drift_mps +
                             config_.pseudorange_rate_sigma_mps * unit(rng);
    m.pseudorange_sigma_m = config_.pseudorange_sigma_m;
    m.pseudorange_rate_sigma_mps = config_.pseudorange_rate_sigma_mps;
    // C/N0 rising with elevation, 35..50 dB-Hz: a common empirical shape.
    m.cn0_dbhz = 35.0 + 15.0 * std::sin(elevation);
    epoch.satellites.push_back(m);
  }
  std::sort(epoch.satellites.begin(), epoch.satellites.end(),
            [](const auto& a, const auto& b) { return a.elevation_rad > b.elevation_rad; });
  if (static_cast<int>(epoch.satellites.size()) > config_.max_satellites) {
    epoch.satellites.resize(static_cast<std::size_t>(config_.max_satellites));
  }
  if (config_.fixed_satellites > 0 && tracked_.empty()) {
    // Keep the N best-placed satellites of the first epoch for the whole run (seed 000 uses 4).
    for (std::size_t i = 0;
         i < epoch.satellites.size() && static_cast<int>(i) < config_.fixed_satellites; ++i) {
      tracked_.push_back(epoch.satellites[i].sv_id);
    }
    epoch.satellites.resize(tracked_.size());
  }
  std::sort(epoch.satellites.begin(), epoch.satellites.end(),
            [](const auto& a, const auto& b) { return a.sv_id < b.sv_id; });
  return epoch;
}

GnssFixSample GnssReceiverModel::fix(const GnssEpoch& epoch, const earth::Geodetic& truth_pos,
                                     const Eigen::Vector3d& truth_vel_ned,
                                     std::mt19937_64& rng) const {
  GnssFixSample f;
  f.time_ns = epoch.time_ns;
  f.num_satellites = static_cast<int>(epoch.satellites.size());
  if (config_.fix_least_squares) {
    std::vector<core::RangeObservation> obs;
    for (const auto& s : epoch.satellites) {
      obs.push_back({s.sat_pos_ecef_m, s.sat_vel_ecef_mps,
                     s.pseudorange_m + s.sat_clock_correction_m,
                     s.pseudorange_rate_mps + s.sat_clock_drift_mps});
    }
    const core::LeastSquaresFix ls = core::leastSquaresFix(obs);
    f.valid = ls.valid;
    if (!ls.valid) return f;
    f.position = earth::ecefToGeodetic(ls.pos_ecef_m);
    const Eigen::Matrix3d C_e_n =
        earth::C_n_e(f.position.latitude_rad, f.position.longitude_rad).transpose();
    f.vel_ned_mps = C_e_n * ls.vel_ecef_mps;
    // Reported 1-sigma: DOP times the receiver's own measurement sigma.
    f.pos_sigma_ned_m =
        Eigen::Vector3d(ls.hdop / std::sqrt(2.0), ls.hdop / std::sqrt(2.0), ls.vdop) *
        config_.pseudorange_sigma_m;
    f.vel_sigma_ned_mps =
        Eigen::Vector3d(ls.hdop / std::sqrt(2.0), ls.hdop / std::sqrt(2.0), ls.vdop) *
        config_.pseudorange_rate_sigma_mps;
    f.pdop = ls.pdop;
    return f;
  }
  std::normal_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d dpos_ned(config_.fix_pos_sigma_m * unit(rng),
                                 config_.fix_pos_sigma_m * unit(rng),
                                 config_.fix_pos_sigma_m * unit(rng));
  f.position = earth::offsetNed(truth_pos, dpos_ned);
  for (int i = 0; i < 3; ++i) {
    f.vel_ned_mps[i] = truth_vel_ned[i] + config_.fix_vel_sigma_mps * unit(rng);
  }
  f.pos_sigma_ned_m.setConstant(config_.fix_pos_sigma_m);
  f.vel_sigma_ned_mps.setConstant(config_.fix_vel_sigma_mps);
  f.valid = f.num_satellites >= 4;
  return f;
}

}  // namespace navbus::sim
