// Raw GNSS observations (RINEX observation + navigation files) into navbus/gnss/observations
// epochs, for the tightly coupled filter. Each epoch is solved by single point positioning
// (core/gnss/single_point_positioning.hpp) only to place the satellites: their positions at
// transmission in the ECEF frame of reception, velocities, clock offsets and drifts come from the
// broadcast ephemeris, and the modelled ionosphere (Klobuchar) and troposphere (Saastamoinen)
// delays are removed from the pseudoranges here, because the bus carries no atmospheric model.
// The pseudorange rate is -lambda_L1 * Doppler. A ramp can be added to one satellite's
// pseudoranges (a fault to detect on real data).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <navbus_idl/Gnss.h>
#include <Eigen/Core>

namespace navbus::importers {

/// A fault added to one satellite's written pseudoranges: rate * (t - onset) after the onset.
struct PseudorangeRamp {
  int sv_id{0};
  double rate_mps{0.0};
  double onset_after_start_s{0.0};  ///< after the first epoch of the observation file
};

struct RinexDescription {
  std::filesystem::path obs;  ///< RINEX 2.10/2.11 observation file (GPS)
  std::filesystem::path nav;  ///< RINEX 2 GPS navigation file
  std::uint32_t receiver_id{1};
  std::string range_type{"C1"};    ///< the pseudorange observable
  std::string doppler_type{"D1"};  ///< the Doppler observable (absent: no rates)
  std::string cn0_type{"S1"};      ///< the signal strength observable (absent: 0 dB-Hz)
  double rate_sigma_mps{0.1};      ///< 1-sigma of a Doppler range rate [m/s]
  /// A pseudorange's 1-sigma: the error budget's (single_point_positioning.hpp) times
  /// `range_sigma_scale`, at least `min_range_sigma_m` [m].
  double range_sigma_scale{1.0};
  double min_range_sigma_m{0.0};
  double elevation_mask_rad{0.0};  ///< satellites below it are left out (counted)
  double time_offset_s{0.0};       ///< added to every epoch's receiver time tag
  std::optional<PseudorangeRamp> ramp;
};

/// An epoch's single point position (the satellites' placement), kept for comparisons.
struct SinglePointEpoch {
  std::int64_t time_ns{0};  ///< GPS time of the solution: receiver time less its clock bias
  Eigen::Vector3d pos_ecef_m{Eigen::Vector3d::Zero()};
  double sigma_h_m{0.0};  ///< from the least-squares covariance, horizontal and vertical
  double sigma_v_m{0.0};
  int used{0};
};

struct ObservationLog {
  std::vector<navbus::GnssObservationEpoch> epochs;
  std::vector<SinglePointEpoch> single_point;  ///< the epochs whose least squares solved
  std::uint64_t epochs_read{0};
  std::uint64_t epochs_unplaced{0};  ///< no position yet to place the satellites from
  std::uint64_t other_systems{0}, missing_range{0}, no_ephemeris{0}, below_mask{0}, bad_range{0},
      no_doppler{0};
  std::uint64_t injected{0};  ///< pseudoranges the ramp changed
  bool has_iono{false};       ///< the navigation file has the broadcast ionosphere model
};

/// Throws bus::ConfigError naming the file, line and field for malformed RINEX.
ObservationLog readRinexObservations(const RinexDescription& d);

}  // namespace navbus::importers
