#include "navbus/core/gnss/single_point_positioning.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "navbus/core/math/earth.hpp"

namespace navbus::core {

namespace {

/// Below this distance from the centre the iterate is not yet on the Earth: no elevation, no
/// atmosphere.
constexpr double kNearSurface_m = 6.0e6;
/// Steps below this keep the elevation mask's selection (0.1 km moves an elevation by less
/// than 0.001 deg).
constexpr double kSelectionLock_m = 100.0;

/// Satellite position at transmission (t_rx - P/c - satellite clock) and its clock.
bool satelliteAtTransmission(double t_rx_s, const PseudorangeObservation& o,
                             const std::vector<gps::BroadcastEphemeris>& ephemerides,
                             gps::SatelliteState& state) {
  const gps::BroadcastEphemeris* eph = gps::selectEphemeris(ephemerides, o.sv_id, t_rx_s);
  if (eph == nullptr) return false;
  double t_tx = t_rx_s - o.pseudorange_m / earth::kSpeedOfLight_mps;
  t_tx -= gps::satelliteClockOffset(*eph, t_tx);  // the offset changes by ps over its own size
  state = gps::satelliteState(*eph, t_tx);
  return true;
}

/// Rotates an ECEF position at transmission into the ECEF frame at reception (Sagnac).
Eigen::Vector3d toReceptionFrame(const Eigen::Vector3d& sat_ecef_m, double travel_s) {
  const double a = gps::kEarthRate_radps * travel_s;
  return Eigen::Vector3d(std::cos(a) * sat_ecef_m.x() + std::sin(a) * sat_ecef_m.y(),
                         -std::sin(a) * sat_ecef_m.x() + std::cos(a) * sat_ecef_m.y(),
                         sat_ecef_m.z());
}

/// The upper bound of the URA interval (IS-GPS-200 20.3.3.3.1.3) that contains `accuracy_m`:
/// the navigation message sends an index, and the index bounds the range error.
double uraBound_m(double accuracy_m) {
  static constexpr double kBounds[] = {2.4,  3.4,   4.85,  6.85,  9.65,   13.65,  24.0,  48.0,
                                       96.0, 192.0, 384.0, 768.0, 1536.0, 3072.0, 6144.0};
  for (double b : kBounds) {
    if (accuracy_m <= b) return b;
  }
  return 6144.0;
}

/// Variance of a corrected pseudorange (the error budget of SinglePointConfig).
double variance(const SinglePointConfig& c, double elevation_rad, double iono_m,
                double accuracy_m) {
  const double s = std::sin(elevation_rad);
  const double receiver =
      c.code_sigma_m * c.code_sigma_m + c.code_sigma_elevation_m * c.code_sigma_elevation_m / s;
  const double iono = c.iono_model_fraction * iono_m;
  const double tropo = c.tropo_sigma_m / (s + 0.1);
  const double ura = uraBound_m(accuracy_m);
  return receiver + c.code_bias_sigma_m * c.code_bias_sigma_m + iono * iono + tropo * tropo +
         ura * ura;
}

}  // namespace

SinglePointSolution solveSinglePoint(double t_rx_s,
                                     const std::vector<PseudorangeObservation>& observations,
                                     const std::vector<gps::BroadcastEphemeris>& ephemerides,
                                     const KlobucharParameters& iono,
                                     const SinglePointConfig& config,
                                     const Eigen::Vector3d& initial_pos_ecef_m) {
  SinglePointSolution sol;
  const std::size_t n = observations.size();
  std::vector<gps::SatelliteState> states(n);
  std::vector<double> accuracy(n, 0.0);
  sol.satellites.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    SinglePointSatellite& s = sol.satellites[i];
    const PseudorangeObservation& o = observations[i];
    s.sv_id = o.sv_id;
    if (!(o.pseudorange_m > 1.0e7 && o.pseudorange_m < 1.0e8)) {
      s.use = SatelliteUse::kBadRange;  // not a GPS signal from medium Earth orbit
    } else if (!satelliteAtTransmission(t_rx_s, o, ephemerides, states[i])) {
      s.use = SatelliteUse::kNoEphemeris;
    } else {
      accuracy[i] = gps::selectEphemeris(ephemerides, o.sv_id, t_rx_s)->accuracy_m;
    }
  }
  std::vector<bool> below_mask(n, false);
  bool locked = false;
  Eigen::Vector4d x(initial_pos_ecef_m.x(), initial_pos_ecef_m.y(), initial_pos_ecef_m.z(), 0.0);
  Eigen::MatrixX4d H(static_cast<Eigen::Index>(n), 4);
  Eigen::VectorXd dz(static_cast<Eigen::Index>(n)), w(static_cast<Eigen::Index>(n));
  for (sol.iterations = 1; sol.iterations <= config.max_iterations; ++sol.iterations) {
    const bool on_surface = x.head<3>().norm() > kNearSurface_m;
    const earth::Geodetic rx = earth::ecefToGeodetic(x.head<3>());
    int rows = 0;
    for (std::size_t i = 0; i < n; ++i) {
      SinglePointSatellite& s = sol.satellites[i];
      if (s.use == SatelliteUse::kNoEphemeris || s.use == SatelliteUse::kBadRange) continue;
      const double travel_s =
          (states[i].pos_ecef_m - x.head<3>()).norm() / earth::kSpeedOfLight_mps;
      const Eigen::Vector3d sat = toReceptionFrame(states[i].pos_ecef_m, travel_s);
      s.use = SatelliteUse::kUsed;
      s.iono_m = s.tropo_m = 0.0;
      double var = 1.0;
      if (on_surface) {
        s.direction = azimuthElevation(rx, sat);
        // The mask is decided while the iterate still moves by more than kSelectionLock_m and
        // then kept: a satellite right at the mask would otherwise enter and leave the
        // selection from one iteration to the next and the iteration would not settle.
        if (!locked) below_mask[i] = s.direction.elevation_rad < config.elevation_mask_rad;
        if (below_mask[i]) {
          s.use = SatelliteUse::kBelowMask;
          continue;
        }
        s.iono_m = klobucharDelay_m(iono, rx, s.direction, t_rx_s);
        s.tropo_m = saastamoinenDelay_m(rx, s.direction.elevation_rad, config.relative_humidity);
        var = variance(config, s.direction.elevation_rad, s.iono_m, accuracy[i]);
      }
      s.sat_clock_m = earth::kSpeedOfLight_mps * states[i].clock_offset_s;
      s.sat_clock_drift_mps = earth::kSpeedOfLight_mps * states[i].clock_drift_sps;
      const double corrected = observations[i].pseudorange_m + s.sat_clock_m - s.iono_m - s.tropo_m;
      const Eigen::Vector3d d = sat - x.head<3>();
      const double range = d.norm();
      H.row(rows) << -d.transpose() / range, 1.0;
      dz[rows] = corrected - (range + x[3]);
      w[rows] = 1.0 / var;
      s.residual_m = dz[rows];
      s.corrected.sv_id = s.sv_id;
      s.corrected.sat_pos_ecef_m = sat;
      s.corrected.sat_vel_ecef_mps = states[i].vel_ecef_mps;
      s.corrected.pseudorange_m = corrected;
      s.corrected.pseudorange_sigma_m = std::sqrt(var);
      s.corrected.use_rate = false;
      ++rows;
    }
    sol.used = rows;
    if (rows < 4) return sol;
    const auto Hu = H.topRows(rows);
    const Eigen::Matrix4d N = Hu.transpose() * w.head(rows).asDiagonal() * Hu;
    const Eigen::Vector4d step =
        N.ldlt().solve(Hu.transpose() * w.head(rows).asDiagonal() * dz.head(rows));
    x += step;
    if (on_surface && step.head<3>().norm() < kSelectionLock_m) locked = true;
    if (on_surface && step.head<3>().norm() < config.convergence_m) {
      sol.valid = true;
      sol.covariance = N.inverse();
      break;
    }
  }
  if (!sol.valid) return sol;
  sol.pos_ecef_m = x.head<3>();
  sol.clock_bias_m = x[3];
  sol.position_sigma_m = std::sqrt(sol.covariance.topLeftCorner<3, 3>().trace());
  // Residuals at the solution (the last iteration's are before its step).
  for (SinglePointSatellite& s : sol.satellites) {
    if (s.use != SatelliteUse::kUsed) continue;
    s.residual_m = s.corrected.pseudorange_m -
                   ((s.corrected.sat_pos_ecef_m - sol.pos_ecef_m).norm() + sol.clock_bias_m);
  }
  return sol;
}

}  // namespace navbus::core
