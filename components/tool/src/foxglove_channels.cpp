#include "navbus/tool/foxglove_channels.hpp"

#include <fmt/format.h>

#include "navbus/bus/gps_time.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/foxglove/schemas.hpp"
#include "navbus/records/message_fields.hpp"

namespace navbus::tool {

namespace {

namespace fg = navbus::foxglove;

constexpr std::uint64_t kNsPerWeek = 604'800ULL * bus::kNsPerSecond;
constexpr const char* kAxisNames[] = {"x", "y", "z"};

/// "GPS week/seconds of week" of a data time.
std::string gpsTimeText(std::uint64_t gps_ns) {
  return fmt::format("GPS {}/{:.3f}", gps_ns / kNsPerWeek,
                     static_cast<double>(gps_ns % kNsPerWeek) / bus::kNsPerSecond);
}

const char* axisName(unsigned axis) {
  return axis < 3 ? kAxisNames[axis] : "?";
}

bool isSensorAxis(navbus::FaultSource s) {
  return s == navbus::SOURCE_ACCELEROMETER || s == navbus::SOURCE_GYRO;
}

/// What a decision or command is about: "SATELLITE G23", "GYRO axis z", "IMU_STREAM 1".
std::string subject(navbus::FaultSource source, unsigned sv_id, unsigned axis, unsigned sensor_id) {
  if (source == navbus::SOURCE_SATELLITE) return fmt::format("SATELLITE G{:02d}", sv_id);
  if (isSensorAxis(source)) {
    return fmt::format("{} axis {} (sensor {})", records::enumName(source), axisName(axis),
                       sensor_id);
  }
  return fmt::format("{} {}", records::enumName(source), sensor_id);
}

DerivedMessage logLine(std::uint64_t unix_ns, fg::LogLevel level, std::string name,
                       std::string message) {
  return DerivedMessage{DerivedChannel::kLog,
                        fg::toJson(fg::Log{unix_ns, level, std::move(message), std::move(name)})};
}

std::string commandDetail(const navbus::FilterCommand& c) {
  switch (c.kind()) {
    case navbus::CMD_EXCLUDE_SATELLITE:
    case navbus::CMD_READMIT_SATELLITE:
      return fmt::format(" G{:02d} ({})", c.sv_id(), records::enumName(c.scope()));
    case navbus::CMD_COMPENSATE_BIAS:
    case navbus::CMD_RELEARN_BIAS:
      return fmt::format(" {} axis {}, bias {:.4g} sigma {:.4g}", records::enumName(c.sensor()),
                         axisName(c.axis()), c.bias(), c.bias_sigma());
    case navbus::CMD_FAIL_SENSOR_AXIS:
    case navbus::CMD_RESTORE_SENSOR_AXIS:
      return fmt::format(" {} axis {}", records::enumName(c.sensor()), axisName(c.axis()));
    case navbus::CMD_SUSPECT_SENSOR_AXIS:
      return fmt::format(" IMU {} {} axis {}", c.sensor_id(), records::enumName(c.sensor()),
                         axisName(c.axis()));
    case navbus::CMD_EXCLUDE_STREAM:
    case navbus::CMD_READMIT_STREAM:
      return fmt::format(" {} {}", records::enumName(c.sensor()), c.sensor_id());
    case navbus::CMD_SELECT_FUSION:
      return fmt::format(" {}", records::enumName(c.fusion()));
    case navbus::CMD_SELECT_MODE:
      return fmt::format(" {}", records::enumName(c.mode()));
    case navbus::CMD_RESET:
      return "";
  }
  return "";
}

}  // namespace

std::array<DerivedChannelSchema, kDerivedChannelCount> derivedChannelSchemas(bool ros2) {
  const std::string prefix = ros2 ? "/" : "";
  return {{{prefix + "navbus/foxglove/location_fix", fg::kLocationFixSchemaName,
            fg::locationFixJsonSchema()},
           {prefix + "navbus/foxglove/log", fg::kLogSchemaName, fg::logJsonSchema()}}};
}

std::optional<DerivedMessage> derivedMessage(const navbus::NavigationSolution& s, std::uint64_t) {
  if (s.output() != navbus::OUTPUT_DETERMINISTIC) return std::nullopt;
  fg::LocationFix fix;
  fix.timestamp_unix_ns = bus::gpsToUnixNs(s.time_gps_ns());
  fix.frame_id = fmt::format("vehicle_{}", s.vehicle_id());
  fix.latitude_deg = s.latitude_rad() / units::kDeg;
  fix.longitude_deg = s.longitude_rad() / units::kDeg;
  fix.altitude_m = s.height_m();
  fix.heading_rad = s.yaw_rad();
  const auto& v_ned = s.vel_ned_mps();
  fix.velocity_enu_mps = {v_ned[1], v_ned[0], -v_ned[2]};
  if (s.covariance_valid()) {
    const auto& sigma_ned = s.pos_sigma_ned_m();
    fix.position_covariance_enu_m2[0] = sigma_ned[1] * sigma_ned[1];  // East
    fix.position_covariance_enu_m2[4] = sigma_ned[0] * sigma_ned[0];  // North
    fix.position_covariance_enu_m2[8] = sigma_ned[2] * sigma_ned[2];  // Up = -Down
    fix.covariance_type = fg::PositionCovarianceType::kDiagonalKnown;
  }
  return DerivedMessage{DerivedChannel::kLocationFix, fg::toJson(fix)};
}

std::optional<DerivedMessage> derivedMessage(const navbus::FaultDecision& d,
                                             std::uint64_t reception_unix_ns) {
  const bool alarm =
      d.event() == navbus::EVENT_FAULT_DETECTED || d.event() == navbus::EVENT_STREAM_LOST;
  std::string text = fmt::format(
      "decision {} at {}: {} {}, statistic {:.4g} against {:.4g}", d.decision_id(),
      gpsTimeText(d.time_gps_ns()), records::enumName(d.event()),
      subject(d.source(), d.sv_id(), d.axis(), d.sensor_id()), d.test_statistic(), d.threshold());
  if (d.shape() != navbus::SHAPE_NONE) {
    text += fmt::format(", {} of {:.4g} since {}", records::enumName(d.shape()), d.magnitude(),
                        gpsTimeText(d.onset_time_gps_ns()));
  }
  if (d.ambiguous()) text += ", ambiguous";
  return logLine(reception_unix_ns, alarm ? fg::LogLevel::kWarning : fg::LogLevel::kInfo,
                 "fault/" + d.detector().to_string(), std::move(text));
}

std::optional<DerivedMessage> derivedMessage(const navbus::FilterCommand& c,
                                             std::uint64_t reception_unix_ns) {
  std::string text =
      fmt::format("command {} to vehicle {} at {}: {}{}", c.command_id(), c.vehicle_id(),
                  gpsTimeText(c.time_gps_ns()), records::enumName(c.kind()), commandDetail(c));
  if (c.decision_id() != 0) text += fmt::format(" (decision {})", c.decision_id());
  return logLine(reception_unix_ns, fg::LogLevel::kInfo, c.issuer().to_string(), std::move(text));
}

std::optional<DerivedMessage> derivedMessage(const navbus::FilterCommandOutcome& o,
                                             std::uint64_t reception_unix_ns) {
  std::string text = fmt::format("command {} of {}: {} {}", o.command_id(), o.issuer().to_string(),
                                 records::enumName(o.kind()), records::enumName(o.outcome()));
  fg::LogLevel level = fg::LogLevel::kInfo;
  if (o.outcome() == navbus::OUTCOME_REFUSED) {
    level = fg::LogLevel::kError;
    text += fmt::format(" ({})", records::enumName(o.reason()));
  } else if (o.outcome() == navbus::OUTCOME_CLAMPED) {
    level = fg::LogLevel::kWarning;
  }
  if (o.detail().size() > 0) text += ": " + o.detail().to_string();
  return logLine(reception_unix_ns, level, fmt::format("filter/vehicle_{}", o.vehicle_id()),
                 std::move(text));
}

}  // namespace navbus::tool
