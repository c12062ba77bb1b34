// Two of Foxglove's published message schemas (foxglove/schemas), the ones its Map and Log
// panels draw: foxglove.LocationFix and foxglove.Log, JSON-encoded (message encoding `json`,
// schema encoding `jsonschema`, as Foxglove takes them over its WebSocket protocol and in MCAP).
// The field names, types and enum values are Foxglove's; the schema texts are written here.
// No DDS: components/tool derives these messages from navbus's own samples.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace navbus::foxglove {

inline constexpr const char* kJsonEncoding = "json";
inline constexpr const char* kJsonSchemaEncoding = "jsonschema";
inline constexpr const char* kLocationFixSchemaName = "foxglove.LocationFix";
inline constexpr const char* kLogSchemaName = "foxglove.Log";

/// foxglove.PositionCovarianceType.
enum class PositionCovarianceType : int {
  kUnknown = 0,
  kApproximated = 1,
  kDiagonalKnown = 2,
  kKnown = 3
};

/// foxglove.LocationFix: a geodetic position with its covariance, for the Map panel.
struct LocationFix {
  std::uint64_t timestamp_unix_ns{0};  ///< time of validity [ns since the Unix epoch, UTC]
  std::string frame_id;
  double latitude_deg{0.0};   ///< [deg, WGS84]
  double longitude_deg{0.0};  ///< [deg, WGS84]
  double altitude_m{0.0};     ///< height above the WGS84 ellipsoid [m]
  /// [m^2] in the local East, North, Up plane through the position, row-major 3 x 3.
  std::array<double, 9> position_covariance_enu_m2{};
  PositionCovarianceType covariance_type{PositionCovarianceType::kUnknown};
  double heading_rad{0.0};                   ///< yaw, clockwise from north [rad]
  std::array<double, 3> velocity_enu_mps{};  ///< [m/s, East North Up]
};

/// foxglove.LogLevel.
enum class LogLevel : int {
  kUnknown = 0,
  kDebug = 1,
  kInfo = 2,
  kWarning = 3,
  kError = 4,
  kFatal = 5
};

/// foxglove.Log: one line for the Log panel.
struct Log {
  std::uint64_t timestamp_unix_ns{0};  ///< [ns since the Unix epoch, UTC]
  LogLevel level{LogLevel::kInfo};
  std::string message;
  std::string name;  ///< who logged it (a participant, a command's issuer)
};

/// The JSON Schema texts of the two messages (draft 2020-12).
const std::string& locationFixJsonSchema();
const std::string& logJsonSchema();

/// The message as JSON bytes (UTF-8, no trailing newline). Non-finite numbers are written as
/// null, as JSON has no NaN.
std::vector<std::uint8_t> toJson(const LocationFix& fix);
std::vector<std::uint8_t> toJson(const Log& log);

}  // namespace navbus::foxglove
