#include "navbus/foxglove/protocol.hpp"

#include <limits>

#include <nlohmann/json.hpp>

namespace navbus::foxglove {

namespace {

using nlohmann::json;

/// At most this many characters of a client's value in a refusal.
constexpr std::size_t kQuotedChars = 80;

std::string quoted(const json& v) {
  std::string text = v.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > kQuotedChars) text = text.substr(0, kQuotedChars) + "...";
  return text;
}

/// An unsigned 32-bit number, or a refusal naming `field`.
bool readId(const json& object, const char* field, const std::string& where, std::uint32_t& out,
            std::string& refusal) {
  const auto it = object.find(field);
  if (it == object.end()) {
    refusal = where + ": no field '" + field + "'";
    return false;
  }
  if (!it->is_number_unsigned() ||
      it->get<std::uint64_t>() > std::numeric_limits<std::uint32_t>::max()) {
    refusal = where + "." + field + ": " + quoted(*it) + " is not an unsigned 32-bit integer";
    return false;
  }
  out = static_cast<std::uint32_t>(it->get<std::uint64_t>());
  return true;
}

const json* arrayField(const json& object, const char* field, std::string& refusal) {
  const auto it = object.find(field);
  if (it == object.end()) {
    refusal = std::string("no field '") + field + "'";
    return nullptr;
  }
  if (!it->is_array()) {
    refusal = std::string(field) + ": " + quoted(*it) + " is not an array";
    return nullptr;
  }
  return &*it;
}

ClientRequest subscribe(const json& message) {
  std::string refusal;
  const json* list = arrayField(message, "subscriptions", refusal);
  if (list == nullptr) return RefusedRequest{"subscribe: " + refusal};
  SubscribeRequest r;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const json& item = (*list)[i];
    const std::string where = "subscribe: subscriptions[" + std::to_string(i) + "]";
    if (!item.is_object()) return RefusedRequest{where + ": " + quoted(item) + " is not an object"};
    Subscription s;
    if (!readId(item, "id", where, s.id, refusal) ||
        !readId(item, "channelId", where, s.channel_id, refusal))
      return RefusedRequest{refusal};
    r.subscriptions.push_back(s);
  }
  return r;
}

ClientRequest unsubscribe(const json& message) {
  std::string refusal;
  const json* list = arrayField(message, "subscriptionIds", refusal);
  if (list == nullptr) return RefusedRequest{"unsubscribe: " + refusal};
  UnsubscribeRequest r;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const json& id = (*list)[i];
    if (!id.is_number_unsigned() ||
        id.get<std::uint64_t>() > std::numeric_limits<std::uint32_t>::max()) {
      return RefusedRequest{"unsubscribe: subscriptionIds[" + std::to_string(i) +
                            "]: " + quoted(id) + " is not an unsigned 32-bit integer"};
    }
    r.subscription_ids.push_back(static_cast<std::uint32_t>(id.get<std::uint64_t>()));
  }
  return r;
}

}  // namespace

std::string serverInfoJson(const std::string& name, const std::string& session_id) {
  return json{{"op", "serverInfo"},
              {"name", name},
              {"capabilities", json::array()},
              {"metadata", json::object()},
              {"sessionId", session_id}}
      .dump();
}

std::string statusJson(StatusLevel level, const std::string& message) {
  return json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}}.dump(
      -1, ' ', false, json::error_handler_t::replace);
}

std::string advertiseJson(const std::vector<Channel>& channels) {
  json list = json::array();
  for (const Channel& c : channels) {
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", c.encoding},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", c.schema_encoding}});
  }
  return json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string unadvertiseJson(const std::vector<std::uint32_t>& channel_ids) {
  return json{{"op", "unadvertise"}, {"channelIds", channel_ids}}.dump();
}

std::vector<std::uint8_t> messageDataHeader(std::uint32_t subscription_id,
                                            std::uint64_t receive_time_ns) {
  std::vector<std::uint8_t> h(kMessageDataHeaderBytes);
  h[0] = 0x01;
  for (int i = 0; i < 4; ++i) h[1 + i] = static_cast<std::uint8_t>(subscription_id >> (8 * i));
  for (int i = 0; i < 8; ++i) h[5 + i] = static_cast<std::uint8_t>(receive_time_ns >> (8 * i));
  return h;
}

ClientRequest parseClientMessage(const std::string& text) {
  const json message = json::parse(text, nullptr, false);
  if (message.is_discarded()) return RefusedRequest{"not JSON: " + quoted(json(text))};
  if (!message.is_object()) return RefusedRequest{"not a JSON object: " + quoted(message)};
  const auto op = message.find("op");
  if (op == message.end()) return RefusedRequest{"no field 'op'"};
  if (!op->is_string()) return RefusedRequest{"op: " + quoted(*op) + " is not a string"};
  const std::string name = op->get<std::string>();
  if (name == "subscribe") return subscribe(message);
  if (name == "unsubscribe") return unsubscribe(message);
  return RefusedRequest{"op " + quoted(*op) +
                        " is not supported (this server takes subscribe and unsubscribe)"};
}

}  // namespace navbus::foxglove
