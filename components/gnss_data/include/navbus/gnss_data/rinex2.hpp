// Readers for RINEX 2.10/2.11 and 3.0x GPS observation and navigation files (Gurtner, "RINEX:
// The Receiver Independent Exchange Format Version 2.10"; IGS/RTCM, "RINEX Version 3.04"): the
// GPS observables of a mixed RINEX 3 file (its "SYS / # / OBS TYPES" for G, e.g. C1C D1C) and
// its GPS ephemerides; other systems' satellites and records are counted. Fixed-column text, read
// line by line; any malformed field stops the read with an error naming the file, the line, the
// field and the text found. What the readers skip on purpose (event records, satellites of other
// systems, satellites without the requested observable) is counted, never dropped silently.
#pragma once

#include <array>
#include <cstdint>
#include <istream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navbus/core/gnss/gnss_atmosphere.hpp"
#include "navbus/core/gnss/gps_broadcast_ephemeris.hpp"
#include "navbus/core/gnss/single_point_positioning.hpp"

namespace navbus::gnss_data {

class RinexError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// GPS time [s since 1980-01-06 00:00:00] of a calendar date and time of day in GPS time.
double gpsSecondsFromCalendar(int year, int month, int day, int hour, int minute, double second);

struct RinexSatelliteObservations {
  char system{'G'};  ///< 'G' GPS (blank in the file means GPS), 'R', 'S', 'E' ...
  int prn{0};
  std::vector<std::optional<double>> values;  ///< per observation type of the header
};

struct RinexObservationEpoch {
  double time_s{0.0};  ///< receiver time tag [GPS s since the GPS epoch]
  int flag{0};         ///< 0 OK, 1 power failure before this epoch
  std::vector<RinexSatelliteObservations> satellites;
};

struct RinexObservationFile {
  std::string version;
  int major_version{2};
  std::string marker;
  /// The GPS observables in file order: "C1", "L1", "P2", ... (RINEX 2), "C1C", "D1C", ...
  /// (RINEX 3, the G line of "SYS / # / OBS TYPES").
  std::vector<std::string> types;
  std::map<char, std::vector<std::string>> system_types;  ///< RINEX 3: every system's
  Eigen::Vector3d approx_position_ecef_m{Eigen::Vector3d::Zero()};
  double interval_s{0.0};
  std::vector<RinexObservationEpoch> epochs;
  // Skipped on purpose, counted.
  std::uint64_t event_records{0};  ///< epoch flags 2-6 with their special records
  /// Index of an observation type, or -1.
  int typeIndex(const std::string& type) const;
};

/// Reads a whole observation file; `name` only labels the errors.
RinexObservationFile readObservationFile(std::istream& in, const std::string& name);

struct RinexNavigationFile {
  std::string version;
  core::KlobucharParameters iono;
  bool has_iono{false};
  int leap_seconds{0};
  std::vector<core::gps::BroadcastEphemeris> ephemerides;
  std::uint64_t other_systems{0};  ///< RINEX 3: records of other systems, skipped
};

/// Reads a whole GPS navigation file (RINEX 2 "N").
RinexNavigationFile readNavigationFile(std::istream& in, const std::string& name);

/// The GPS pseudoranges of one epoch for an observation type (e.g. "C1"). Satellites of other
/// systems and satellites without that observable are counted in `skipped`.
struct EpochPseudoranges {
  std::vector<core::PseudorangeObservation> observations;
  int other_systems{0};
  int missing{0};
};
EpochPseudoranges pseudoranges(const RinexObservationEpoch& epoch, int type_index);

}  // namespace navbus::gnss_data
