// The Foxglove WebSocket protocol, subprotocol foxglove.websocket.v1 (foxglove/ws-protocol,
// docs/spec.md), as a server speaks it: the JSON messages it sends (Server Info, Status,
// Advertise, Unadvertise), the binary Message Data frame, and the client's Subscribe and
// Unsubscribe read and validated. No network here: ws_server.hpp carries these bytes.
#pragma once

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace navbus::foxglove {

inline constexpr const char* kSubprotocol = "foxglove.websocket.v1";

/// One stream the server offers.
struct Channel {
  std::uint32_t id{0};
  std::string topic;
  std::string encoding;         ///< the messages' encoding: cdr, json
  std::string schema_name;      ///< e.g. navbus::NavigationSolution, foxglove.LocationFix
  std::string schema;           ///< the schema text
  std::string schema_encoding;  ///< omgidl, ros2msg, jsonschema
};

enum class StatusLevel : int { kInfo = 0, kWarning = 1, kError = 2 };

std::string serverInfoJson(const std::string& name, const std::string& session_id);
std::string statusJson(StatusLevel level, const std::string& message);
std::string advertiseJson(const std::vector<Channel>& channels);
std::string unadvertiseJson(const std::vector<std::uint32_t>& channel_ids);

/// The Message Data frame's first 13 bytes: opcode 0x01, the subscription id (uint32) and the
/// receive time [ns] (uint64), little-endian; the payload follows as it is.
std::vector<std::uint8_t> messageDataHeader(std::uint32_t subscription_id,
                                            std::uint64_t receive_time_ns);
inline constexpr std::size_t kMessageDataHeaderBytes = 13;

struct Subscription {
  std::uint32_t id{0};
  std::uint32_t channel_id{0};
};
struct SubscribeRequest {
  std::vector<Subscription> subscriptions;
};
struct UnsubscribeRequest {
  std::vector<std::uint32_t> subscription_ids;
};
/// A text message the server refuses, with the reason for the client's Status.
struct RefusedRequest {
  std::string reason;
};
using ClientRequest = std::variant<SubscribeRequest, UnsubscribeRequest, RefusedRequest>;

/// Reads one text message of a client. Anything but a JSON object with op "subscribe" (an
/// array `subscriptions` of {id, channelId}, unsigned 32-bit numbers) or "unsubscribe" (an
/// array `subscriptionIds`) is refused, naming the field and the value.
ClientRequest parseClientMessage(const std::string& text);

}  // namespace navbus::foxglove
