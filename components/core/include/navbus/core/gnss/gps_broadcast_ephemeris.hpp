// GPS satellite position and clock from the broadcast navigation message (IS-GPS-200:
// user algorithm for ephemeris determination 20.3.3.4.3, Table 20-IV; satellite clock
// correction 20.3.3.3.3.1 with the relativistic term and the L1 group delay of 20.3.3.3.3.2).
// Times are GPS system time in seconds since the GPS epoch (1980-01-06 00:00:00): a double
// resolves 0.12 us there (0.5 mm of satellite motion), enough for pseudorange positioning.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace navbus::core::gps {

// Constants the interface specification fixes for the user algorithm (they differ from
// WGS84's in earth.hpp in the last digits, and the broadcast orbit is fitted with these).
inline constexpr double kGm_m3ps2 = 3.986005e14;                    ///< mu, IS-GPS-200 Table 20-IV
inline constexpr double kEarthRate_radps = 7.2921151467e-5;         ///< Omega_e dot, Table 20-IV
inline constexpr double kRelativisticF_spsqrtm = -4.442807633e-10;  ///< F, 20.3.3.3.3.1
inline constexpr double kPi = 3.1415926535898;                      ///< the pi of 20.3.3.4.3
inline constexpr double kSecondsPerWeek = 604800.0;
/// How far from toe a broadcast ephemeris is used: half of the 4 h curve fit interval.
inline constexpr double kMaxEphemerisAge_s = 7200.0;

/// One broadcast ephemeris and clock set (subframes 1-3) of one satellite, SI units; angles
/// in radians (as RINEX navigation files carry them; the navigation message itself sends
/// semicircles).
struct BroadcastEphemeris {
  int sv_id{0};
  double toc_s{0.0};  ///< clock reference time [s since the GPS epoch]
  double toe_s{0.0};  ///< ephemeris reference time [s since the GPS epoch]
  double af0_s{0.0}, af1_sps{0.0}, af2_sps2{0.0};  ///< clock polynomial
  double tgd_s{0.0};                               ///< L1/L2 group delay differential
  double sqrt_a_sqrtm{0.0};                        ///< square root of the semi-major axis
  double eccentricity{0.0};
  double m0_rad{0.0};                   ///< mean anomaly at toe
  double delta_n_radps{0.0};            ///< mean motion difference
  double omega0_rad{0.0};               ///< longitude of the ascending node at the week's start
  double omega_dot_radps{0.0};          ///< rate of right ascension
  double i0_rad{0.0}, idot_radps{0.0};  ///< inclination at toe and its rate
  double argument_of_perigee_rad{0.0};  ///< omega
  double cuc_rad{0.0}, cus_rad{0.0};    ///< argument of latitude harmonic corrections
  double crc_m{0.0}, crs_m{0.0};        ///< orbit radius harmonic corrections
  double cic_rad{0.0}, cis_rad{0.0};    ///< inclination harmonic corrections
  double iode{0.0};
  double accuracy_m{0.0};  ///< user range accuracy (URA) [m]
  int health{0};           ///< 0: healthy
};

struct SatelliteState {
  Eigen::Vector3d pos_ecef_m{Eigen::Vector3d::Zero()};    ///< ECEF at the evaluation time
  Eigen::Vector3d vel_ecef_mps{Eigen::Vector3d::Zero()};  ///< w.r.t. the rotating ECEF frame
  /// Satellite clock offset for an L1 single-frequency user: polynomial + relativistic - TGD.
  double clock_offset_s{0.0};
  double clock_drift_sps{0.0};
};

/// Satellite clock offset (polynomial and relativistic term, minus TGD) at GPS time t.
double satelliteClockOffset(const BroadcastEphemeris& eph, double t_s);

/// Position (Table 20-IV) and clock at GPS time t. The velocity is the central difference of
/// the same algorithm over +-1 ms (the orbit is smooth there to far below a mm/s).
SatelliteState satelliteState(const BroadcastEphemeris& eph, double t_s);

/// The ephemeris of `sv_id` whose toe is closest to t, healthy and within
/// kMaxEphemerisAge_s of t; nullptr if there is none.
const BroadcastEphemeris* selectEphemeris(const std::vector<BroadcastEphemeris>& set, int sv_id,
                                          double t_s);

}  // namespace navbus::core::gps
