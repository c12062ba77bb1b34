// A data set description: the small YAML file that tells `navbus import` how to read a user's
// logs (an IMU CSV file and its clock, RTKLIB solutions, RINEX files) into a navbus recording.
// Parsed with the configuration's KeyReader: every key range-checked in the file's unit and
// converted to SI once, an unknown key refused. File paths are relative to the YAML file.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "navbus/importers/rinex_observations.hpp"

namespace navbus::importers {

/// A fault added to one axis of the written IMU samples: a constant `step` in the sensor's axes
/// from the onset on (an accelerometer [m/s^2] or gyro [rad/s] bias step, for the detectors to
/// find on real data).
struct ImuStep {
  bool gyro{false};                 ///< false: the accelerometer
  int axis{0};                      ///< sensor axis 0..2 (x y z of the file's columns)
  double step{0.0};                 ///< [m/s^2] or [rad/s]
  double onset_after_start_s{0.0};  ///< after the first sample of the file
};

/// Where an IMU sample's GPS time comes from.
enum class ImuTimeSource {
  kDeviceTicks,       ///< a device counter column mapped by an RTKLIB time-tag file
  kGpsSecondsOfWeek,  ///< a column of GPS seconds of week, with the GPS week in the description
  kGpsSeconds,        ///< a column of GPS seconds since 1980-01-06 00:00:00
};

struct ImuCsvDescription {
  std::filesystem::path file;
  std::uint32_t sensor_id{1};
  std::size_t header_lines{0};  ///< lines before the first sample (not parsed)
  /// 0-based columns of the specific force (x y z), the angular rate (x y z) and the time, in
  /// the sensor's own axes (the filter's imu.mounting turns them into the body frame).
  std::array<std::size_t, 3> accel_columns{0, 1, 2};
  std::array<std::size_t, 3> gyro_columns{3, 4, 5};
  std::size_t time_column{6};
  double accel_to_mps2{1.0};   ///< the file's specific-force unit in m/s^2 (accel_unit)
  double gyro_to_radps{1.0};   ///< the file's angular-rate unit in rad/s (gyro_unit)
  double sample_rate_hz{0.0};  ///< nominal; the intervals come from the time column
  ImuTimeSource time_source{ImuTimeSource::kDeviceTicks};
  double tick_s{1e-3};             ///< device ticks: seconds per tick
  std::filesystem::path time_tag;  ///< device ticks: the RTKLIB time-tag file
  std::uint32_t gps_week{0};       ///< seconds of week: the week
  double time_offset_s{0.0};       ///< added to every sample's time (logging delays)
  double block_s{0.1};             ///< increments per recorded block, as time
  std::optional<ImuStep> step;     ///< a fault injected into the written samples
};

/// How one RTKLIB solution quality is used: its sigmas are the file's times `sigma_scale`, at
/// least the floors; `use: false` leaves the quality's epochs out (counted).
struct QualityUse {
  bool use{true};
  double sigma_scale{1.0};
  double min_position_sigma_m{0.0};
  double min_velocity_sigma_mps{0.0};
};

/// RTKLIB's Q column: 1 fix, 2 float, 3 SBAS, 4 DGPS, 5 single, 6 PPP.
inline constexpr std::array<const char*, 7> kQualityNames{"",     "fix",    "float", "sbas",
                                                          "dgps", "single", "ppp"};

struct PosDescription {
  std::filesystem::path file;
  std::uint32_t receiver_id{1};
  double time_offset_s{0.0};  ///< added to every epoch's time stamp
  /// Added to the file's heights to make them ellipsoidal (WGS84): 0 for ellipsoidal heights,
  /// the geoid separation N for heights above mean sea level (h = H + N).
  double height_to_ellipsoid_m{0.0};
  /// The fix's velocity sigma when the file has no velocity columns (position only) [m/s].
  double velocity_sigma_when_absent_mps{100.0};
  std::array<QualityUse, kQualityNames.size()> quality{};
};

struct DatasetDescription {
  std::filesystem::path file;  ///< the YAML file itself
  std::string name;
  std::optional<ImuCsvDescription> imu;
  std::optional<PosDescription> gnss_solutions;
  std::optional<RinexDescription> gnss_observations;
};

/// Reads a data set description; throws bus::ConfigError naming the key and the value.
DatasetDescription readDatasetDescription(const std::filesystem::path& yaml_file);

}  // namespace navbus::importers
