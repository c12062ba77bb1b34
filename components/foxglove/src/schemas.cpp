#include "navbus/foxglove/schemas.hpp"

#include <nlohmann/json.hpp>

namespace navbus::foxglove {

namespace {

using nlohmann::json;

constexpr std::uint64_t kNsPerS = 1'000'000'000ULL;

/// foxglove.Time / builtin time: whole seconds and nanoseconds.
json timeJson(std::uint64_t unix_ns) {
  return json{{"sec", unix_ns / kNsPerS}, {"nsec", unix_ns % kNsPerS}};
}

json timeSchema(const char* description) {
  return json{{"type", "object"},
              {"title", "time"},
              {"description", description},
              {"properties",
               {{"sec", {{"type", "integer"}, {"minimum", 0}}},
                {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}}},
              {"required", {"sec", "nsec"}}};
}

/// An enum as Foxglove's JSON schemas give one: a oneOf of titled constants.
json enumSchema(const char* title, const char* description,
                std::initializer_list<std::pair<const char*, int>> values) {
  json one_of = json::array();
  for (const auto& [name, value] : values) one_of.push_back({{"title", name}, {"const", value}});
  return json{{"title", title}, {"description", description}, {"oneOf", one_of}};
}

json number(const char* description) {
  return json{{"type", "number"}, {"description", description}};
}

std::string makeLocationFixSchema() {
  json properties = {
      {"timestamp", timeSchema("Time of validity of the fix")},
      {"frame_id", {{"type", "string"}, {"description", "Frame of the fix (the vehicle)"}}},
      {"latitude", number("Latitude [deg, WGS84]")},
      {"longitude", number("Longitude [deg, WGS84]")},
      {"altitude", number("Height above the WGS84 ellipsoid [m]")},
      {"position_covariance",
       {{"type", "array"},
        {"description",
         "Position covariance [m^2] in the East, North, Up plane through the "
         "position, row-major"},
        {"items", {{"type", "number"}}},
        {"minItems", 9},
        {"maxItems", 9}}},
      {"position_covariance_type",
       enumSchema("foxglove.PositionCovarianceType", "How position_covariance is known",
                  {{"UNKNOWN", 0}, {"APPROXIMATED", 1}, {"DIAGONAL_KNOWN", 2}, {"KNOWN", 3}})},
      {"heading", number("Yaw, clockwise from north [rad]")},
      {"velocity",
       {{"title", "foxglove.Vector3"},
        {"description", "Velocity [m/s, East North Up]"},
        {"type", "object"},
        {"properties",
         {{"x", number("East [m/s]")}, {"y", number("North [m/s]")}, {"z", number("Up [m/s]")}}},
        {"required", {"x", "y", "z"}}}}};
  return json{{"title", kLocationFixSchemaName},
              {"description", "A geodetic position fix with its covariance"},
              {"type", "object"},
              {"properties", properties},
              {"required",
               {"timestamp", "frame_id", "latitude", "longitude", "altitude", "position_covariance",
                "position_covariance_type"}}}
      .dump();
}

std::string makeLogSchema() {
  json properties = {
      {"timestamp", timeSchema("Time of the event")},
      {"level", enumSchema("foxglove.LogLevel", "Severity",
                           {{"UNKNOWN", 0},
                            {"DEBUG", 1},
                            {"INFO", 2},
                            {"WARNING", 3},
                            {"ERROR", 4},
                            {"FATAL", 5}})},
      {"message", {{"type", "string"}, {"description", "The text"}}},
      {"name", {{"type", "string"}, {"description", "Who logged it"}}},
      {"file", {{"type", "string"}, {"description", "Source file (empty)"}}},
      {"line", {{"type", "integer"}, {"minimum", 0}, {"description", "Source line (0)"}}}};
  return json{{"title", kLogSchemaName},
              {"description", "A log message"},
              {"type", "object"},
              {"properties", properties},
              {"required", {"timestamp", "level", "message", "name", "file", "line"}}}
      .dump();
}

std::vector<std::uint8_t> bytesOf(const json& j) {
  const std::string text = j.dump(-1, ' ', false, json::error_handler_t::replace);
  return {text.begin(), text.end()};
}

}  // namespace

const std::string& locationFixJsonSchema() {
  static const std::string schema = makeLocationFixSchema();
  return schema;
}

const std::string& logJsonSchema() {
  static const std::string schema = makeLogSchema();
  return schema;
}

std::vector<std::uint8_t> toJson(const LocationFix& fix) {
  return bytesOf(json{{"timestamp", timeJson(fix.timestamp_unix_ns)},
                      {"frame_id", fix.frame_id},
                      {"latitude", fix.latitude_deg},
                      {"longitude", fix.longitude_deg},
                      {"altitude", fix.altitude_m},
                      {"position_covariance", fix.position_covariance_enu_m2},
                      {"position_covariance_type", static_cast<int>(fix.covariance_type)},
                      {"heading", fix.heading_rad},
                      {"velocity",
                       {{"x", fix.velocity_enu_mps[0]},
                        {"y", fix.velocity_enu_mps[1]},
                        {"z", fix.velocity_enu_mps[2]}}}});
}

std::vector<std::uint8_t> toJson(const Log& log) {
  return bytesOf(json{{"timestamp", timeJson(log.timestamp_unix_ns)},
                      {"level", static_cast<int>(log.level)},
                      {"message", log.message},
                      {"name", log.name},
                      {"file", ""},
                      {"line", 0}});
}

}  // namespace navbus::foxglove
