// Channels in Foxglove's own schemas, derived from navbus's samples so that Foxglove's panels
// draw the bus without a user script: the deterministic solution as foxglove.LocationFix (Map
// panel, with its horizontal and vertical sigmas as the covariance), and fault decisions,
// filter commands and the filter's answers as foxglove.Log lines (Log panel). Served live by
// `navbus foxglove` and written by `navbus record --format mcap --foxglove`.
#pragma once

#include <navbus_idl/Fault.h>
#include <navbus_idl/Navigation.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace navbus::tool {

enum class DerivedChannel : std::size_t { kLocationFix = 0, kLog = 1 };
inline constexpr std::size_t kDerivedChannelCount = 2;

/// A derived channel as it is advertised or recorded: JSON messages with a JSON Schema.
struct DerivedChannelSchema {
  std::string topic;  ///< navbus/foxglove/location_fix, navbus/foxglove/log ("/" first: ROS 2)
  std::string schema_name;
  std::string schema;
};
/// The derived channels, in DerivedChannel order.
std::array<DerivedChannelSchema, kDerivedChannelCount> derivedChannelSchemas(bool ros2);

struct DerivedMessage {
  DerivedChannel channel{DerivedChannel::kLog};
  std::vector<std::uint8_t> json;
};

/// A deterministic solution as a LocationFix stamped with its time of validity (in UTC):
/// position in degrees, covariance diagonal from the N E D sigmas turned into East, North, Up
/// (UNKNOWN, all zero, when covariance_valid is false: the sigmas are not to be used). The
/// low-latency output derives nothing.
std::optional<DerivedMessage> derivedMessage(const navbus::NavigationSolution& solution,
                                             std::uint64_t reception_unix_ns);
/// Log lines are stamped with the time the bus carried the sample (`reception_unix_ns`; an
/// outcome has no data time) and give the data time in their text.
/// A decision: WARNING for a detected fault or a lost stream, INFO otherwise.
std::optional<DerivedMessage> derivedMessage(const navbus::FaultDecision& decision,
                                             std::uint64_t reception_unix_ns);
/// A command: INFO, named by its issuer.
std::optional<DerivedMessage> derivedMessage(const navbus::FilterCommand& command,
                                             std::uint64_t reception_unix_ns);
/// The filter's answer: INFO applied, WARNING clamped, ERROR refused.
std::optional<DerivedMessage> derivedMessage(const navbus::FilterCommandOutcome& outcome,
                                             std::uint64_t reception_unix_ns);
/// Every other type derives nothing.
template <class T>
std::optional<DerivedMessage> derivedMessage(const T&, std::uint64_t) {
  return std::nullopt;
}

}  // namespace navbus::tool
