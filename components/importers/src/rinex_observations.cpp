#include "navbus/importers/rinex_observations.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "navbus/bus/config.hpp"
#include "navbus/core/gnss/single_point_positioning.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/gnss_data/rinex2.hpp"

namespace navbus::importers {

namespace {

constexpr double kL1Hz = 1575.42e6;
constexpr double kL1Wavelength_m = core::earth::kSpeedOfLight_mps / kL1Hz;

template <class File>
File readFile(const std::filesystem::path& path,
              File (*reader)(std::istream&, const std::string&)) {
  std::ifstream in(path);
  if (!in) throw bus::ConfigError(path.string() + ": cannot be read");
  try {
    return reader(in, path.string());
  } catch (const gnss_data::RinexError& e) {
    throw bus::ConfigError(e.what());
  }
}

/// The value of an optional observable of one satellite, or nullopt.
std::optional<double> observable(const gnss_data::RinexObservationEpoch& e, int sv_id, int type) {
  if (type < 0) return std::nullopt;
  for (const auto& s : e.satellites) {
    if (s.system == 'G' && s.prn == sv_id && static_cast<std::size_t>(type) < s.values.size())
      return s.values[static_cast<std::size_t>(type)];
  }
  return std::nullopt;
}

class EpochPlacer {
 public:
  EpochPlacer(const RinexDescription& d, const gnss_data::RinexObservationFile& obs,
              const gnss_data::RinexNavigationFile& nav, ObservationLog& log)
      : d_(d), obs_(obs), nav_(nav), log_(log) {
    range_ = obs.typeIndex(d.range_type);
    if (range_ < 0)
      throw bus::ConfigError(d.obs.string() + ": no '" + d.range_type +
                             "' observable (data set gnss_observations.range_type)");
    doppler_ = obs.typeIndex(d.doppler_type);
    cn0_ = obs.typeIndex(d.cn0_type);
    spp_.elevation_mask_rad = d.elevation_mask_rad;
  }

  void place(const gnss_data::RinexObservationEpoch& e) {
    ++log_.epochs_read;
    gnss_data::EpochPseudoranges raw = gnss_data::pseudoranges(e, range_);
    log_.other_systems += static_cast<std::uint64_t>(raw.other_systems);
    log_.missing_range += static_cast<std::uint64_t>(raw.missing);
    const core::SinglePointSolution fix = core::solveSinglePoint(
        e.time_s, raw.observations, nav_.ephemerides, nav_.iono, spp_, last_position_);
    if (fix.valid) {
      last_position_ = fix.pos_ecef_m;
      keep(e.time_s, fix);
    }
    if (last_position_.isZero()) {  // nowhere to place the satellites from yet
      ++log_.epochs_unplaced;
      return;
    }
    navbus::GnssObservationEpoch out;
    out.receiver_id(d_.receiver_id);
    out.seq(log_.epochs.size() + 1);
    out.time_gps_ns(static_cast<std::uint64_t>(std::llround((e.time_s + d_.time_offset_s) * 1e9)));
    for (const core::SinglePointSatellite& s : fix.satellites) {
      if (s.use == core::SatelliteUse::kNoEphemeris) ++log_.no_ephemeris;
      if (s.use == core::SatelliteUse::kBelowMask) ++log_.below_mask;
      if (s.use == core::SatelliteUse::kBadRange) ++log_.bad_range;
      if (s.use != core::SatelliteUse::kUsed) continue;
      if (out.satellites().size() == 32) break;  // the IDL's bound; a GPS epoch never reaches it
      out.satellites().push_back(measurement(e, s));
    }
    log_.epochs.push_back(std::move(out));
  }

 private:
  navbus::GnssSatelliteMeasurement measurement(const gnss_data::RinexObservationEpoch& e,
                                               const core::SinglePointSatellite& s) {
    navbus::GnssSatelliteMeasurement m;
    m.sv_id(static_cast<std::uint16_t>(s.sv_id));
    // The pseudorange as received less the modelled atmosphere: corrected = this + sat clock.
    m.pseudorange_m(s.corrected.pseudorange_m - s.sat_clock_m + injected(e.time_s, s.sv_id));
    m.sat_clock_correction_m(s.sat_clock_m);
    m.sat_clock_drift_mps(s.sat_clock_drift_mps);
    for (int i = 0; i < 3; ++i) {
      m.sat_pos_ecef_m()[static_cast<std::size_t>(i)] = s.corrected.sat_pos_ecef_m[i];
      m.sat_vel_ecef_mps()[static_cast<std::size_t>(i)] = s.corrected.sat_vel_ecef_mps[i];
    }
    m.pseudorange_sigma_m(
        std::max(s.corrected.pseudorange_sigma_m * d_.range_sigma_scale, d_.min_range_sigma_m));
    const std::optional<double> doppler = observable(e, s.sv_id, doppler_);
    if (doppler) {
      m.pseudorange_rate_mps(-kL1Wavelength_m * *doppler);
      m.pseudorange_rate_sigma_mps(d_.rate_sigma_mps);
    } else {
      ++log_.no_doppler;
      m.pseudorange_rate_mps(0.0);
      m.pseudorange_rate_sigma_mps(1e3);  // no rate: a sigma that carries no information
    }
    const std::optional<double> cn0 = observable(e, s.sv_id, cn0_);
    m.cn0_dbhz(cn0 ? std::clamp(*cn0, 0.0, 70.0) : 0.0);
    m.valid(true);
    return m;
  }

  void keep(double t_rx_s, const core::SinglePointSolution& fix) {
    const core::earth::Geodetic p = core::earth::ecefToGeodetic(fix.pos_ecef_m);
    const Eigen::Matrix3d C_n_e = core::earth::C_n_e(p.latitude_rad, p.longitude_rad);
    const Eigen::Matrix3d cov_ned =
        C_n_e.transpose() * fix.covariance.topLeftCorner<3, 3>() * C_n_e;
    const double t_s =
        t_rx_s + d_.time_offset_s - fix.clock_bias_m / core::earth::kSpeedOfLight_mps;
    log_.single_point.push_back({static_cast<std::int64_t>(std::llround(t_s * 1e9)), fix.pos_ecef_m,
                                 std::sqrt(cov_ned(0, 0) + cov_ned(1, 1)), std::sqrt(cov_ned(2, 2)),
                                 fix.used});
  }

  /// The ramp's contribution to one pseudorange [m]. It is added to what is written, after the
  /// satellites are placed from the clean epoch: the placement is this importer's device, and
  /// a fault in it would leak centimetres into the other satellites' modelled delays.
  double injected(double t_s, int sv_id) {
    if (!d_.ramp || d_.ramp->sv_id != sv_id || obs_.epochs.empty()) return 0.0;
    const double dt = t_s - obs_.epochs.front().time_s - d_.ramp->onset_after_start_s;
    if (dt <= 0.0) return 0.0;
    ++log_.injected;
    return d_.ramp->rate_mps * dt;
  }

  const RinexDescription& d_;
  const gnss_data::RinexObservationFile& obs_;
  const gnss_data::RinexNavigationFile& nav_;
  ObservationLog& log_;
  core::SinglePointConfig spp_;
  int range_{-1}, doppler_{-1}, cn0_{-1};
  Eigen::Vector3d last_position_{Eigen::Vector3d::Zero()};
};

}  // namespace

ObservationLog readRinexObservations(const RinexDescription& d) {
  const gnss_data::RinexObservationFile obs = readFile(d.obs, &gnss_data::readObservationFile);
  const gnss_data::RinexNavigationFile nav = readFile(d.nav, &gnss_data::readNavigationFile);
  ObservationLog log;
  log.has_iono = nav.has_iono;
  EpochPlacer placer(d, obs, nav, log);
  for (const gnss_data::RinexObservationEpoch& e : obs.epochs) placer.place(e);
  return log;
}

}  // namespace navbus::importers
