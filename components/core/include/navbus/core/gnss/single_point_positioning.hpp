// Single-epoch GPS positioning from L1 pseudoranges and the broadcast navigation message:
// satellite positions and clocks per IS-GPS-200 (gps_broadcast_ephemeris.hpp), Earth rotation
// during signal travel (Sagnac), Klobuchar ionosphere and Saastamoinen troposphere
// (gnss_atmosphere.hpp), an elevation mask and weighted Gauss-Newton least squares for
// position and receiver clock. It also hands out each satellite's corrected measurement in
// the form the filters take (SatelliteObservation), so that a filter fed from real data sees
// the same corrections as the least-squares fix.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "navbus/core/gnss/gnss_atmosphere.hpp"
#include "navbus/core/gnss/gnss_measurement.hpp"
#include "navbus/core/gnss/gps_broadcast_ephemeris.hpp"

namespace navbus::core {

/// One raw code measurement as a receiver reports it.
struct PseudorangeObservation {
  int sv_id{0};
  double pseudorange_m{0.0};  ///< C/A code pseudorange [m]
};

/// Error budget of a corrected pseudorange, used as its weight: the variance is
///   a^2 + b^2 / sin(el)             receiver noise and multipath
/// + d^2                             unmodelled code bias
/// + (f * I)^2                       what the broadcast ionosphere model I leaves
/// + (c / (sin(el) + 0.1))^2         troposphere model error
/// + URA^2                           ephemeris and satellite clock (upper bound of the URA
///                                   index interval the navigation message sends).
/// The defaults are those of RTKLIB's single point mode (its manual, appendix E: the same
/// terms, including b^2 / sin(el) rather than / sin^2), so that the two solutions weight
/// satellites alike and can be compared epoch by epoch.
struct SinglePointConfig {
  double elevation_mask_rad{10.0 * M_PI / 180.0};
  double relative_humidity{0.7};       ///< for the Saastamoinen wet delay
  double code_sigma_m{0.3};            ///< a
  double code_sigma_elevation_m{0.3};  ///< b
  double code_bias_sigma_m{0.3};       ///< d
  double iono_model_fraction{0.5};     ///< f: residual ionosphere / modelled delay
  double tropo_sigma_m{0.3};           ///< c
  int max_iterations{10};
  double convergence_m{1e-4};  ///< stop when the position step is below this
};

enum class SatelliteUse { kUsed, kNoEphemeris, kBelowMask, kBadRange };

struct SinglePointSatellite {
  int sv_id{0};
  SatelliteUse use{SatelliteUse::kUsed};
  AzimuthElevation direction;
  double sat_clock_m{0.0};          ///< c * satellite clock offset (added to the pseudorange)
  double sat_clock_drift_mps{0.0};  ///< c * satellite clock drift (added to the range rate)
  double iono_m{0.0};               ///< modelled delays (subtracted)
  double tropo_m{0.0};
  double residual_m{0.0};  ///< corrected pseudorange minus modelled range and clock, at the fix
  /// The corrected measurement: satellite at transmission expressed in the ECEF frame of
  /// reception, pseudorange with satellite clock, ionosphere and troposphere removed, and its
  /// sigma from the error budget (rate unused: no Doppler).
  SatelliteObservation corrected;
};

struct SinglePointSolution {
  bool valid{false};  ///< false: fewer than 4 usable satellites or no convergence
  Eigen::Vector3d pos_ecef_m{Eigen::Vector3d::Zero()};
  double clock_bias_m{0.0};                             ///< c * receiver clock bias
  Eigen::Matrix4d covariance{Eigen::Matrix4d::Zero()};  ///< of (x y z [m] ECEF, clock [m])
  int used{0};
  int iterations{0};
  double position_sigma_m{0.0};  ///< sqrt(trace) of the position block of `covariance`
  std::vector<SinglePointSatellite> satellites;  ///< in the order of the observations
};

/// Solves one epoch received at GPS time t_rx [s since the GPS epoch, the receiver's time
/// tag]. `initial_pos_ecef_m` may be zero (the centre of the Earth): corrections and the
/// elevation mask then start once the iteration has reached the Earth's surface.
SinglePointSolution solveSinglePoint(double t_rx_s,
                                     const std::vector<PseudorangeObservation>& observations,
                                     const std::vector<gps::BroadcastEphemeris>& ephemerides,
                                     const KlobucharParameters& iono,
                                     const SinglePointConfig& config,
                                     const Eigen::Vector3d& initial_pos_ecef_m);

}  // namespace navbus::core
