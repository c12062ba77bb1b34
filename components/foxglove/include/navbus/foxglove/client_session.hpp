// One connected client of the Foxglove bridge: its subscriptions, and what waits to be sent to
// it. Data frames wait in a bounded queue per subscription (the oldest dropped and counted when
// a client reads slower than the bus writes), so a slow client never holds up the bus or the
// other clients. No network and no locks here: ws_server.cpp owns one per connection.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "navbus/foxglove/protocol.hpp"

namespace navbus::foxglove {

/// A message's payload, shared by every client that gets it.
using Payload = std::shared_ptr<const std::vector<std::uint8_t>>;

/// A Message Data frame for one subscription: its 13-byte header, then the payload.
struct DataFrame {
  std::vector<std::uint8_t> header;
  Payload payload;
};
/// What goes out next: a JSON text message or a binary data frame.
using Outgoing = std::variant<std::string, DataFrame>;

struct SessionCounters {
  std::uint64_t frames_queued{0};
  std::uint64_t frames_dropped{0};  ///< the oldest of a full subscription queue, dropped
  std::map<std::uint32_t, std::uint64_t> dropped_by_channel;
  std::uint64_t requests_refused{0};
  std::uint64_t statuses_dropped{0};  ///< refusals not queued: the client does not read them
};

class ClientSession {
 public:
  /// `frames_per_subscription` data frames wait at most per subscription; `max_texts` text
  /// messages (beyond them status replies are dropped, an advertisement overflows the session).
  ClientSession(std::size_t frames_per_subscription, std::size_t max_texts);

  /// Applies one text message of the client; `channel_exists` says whether a channel id is on
  /// offer. Refusals and odd requests are answered with a Status (queued).
  void handleText(const std::string& text,
                  const std::function<bool(std::uint32_t)>& channel_exists);
  /// The client sent a binary message: this server takes none (no clientPublish capability).
  void handleBinary();
  /// A message of `channel_id`: queued if the client subscribed to the channel. Returns whether.
  bool offer(std::uint32_t channel_id, std::uint64_t receive_time_ns, const Payload& payload);
  /// A server message (Advertise, Unadvertise, Status) for this client.
  void pushText(std::string text);
  /// The channel is no longer offered: its subscription ends, its queued frames go.
  void channelGone(std::uint32_t channel_id);
  /// The next message to send, control messages first, then the subscriptions in turn.
  std::optional<Outgoing> next();

  bool overflowed() const { return overflowed_; }
  std::size_t subscriptions() const { return channel_of_subscription_.size(); }
  const SessionCounters& counters() const { return counters_; }

 private:
  void refuse(const std::string& reason);
  void subscribe(const SubscribeRequest& r,
                 const std::function<bool(std::uint32_t)>& channel_exists);
  void unsubscribe(const UnsubscribeRequest& r);

  std::size_t frames_per_subscription_;
  std::size_t max_texts_;
  std::deque<std::string> texts_;
  std::map<std::uint32_t, std::uint32_t> channel_of_subscription_;
  std::map<std::uint32_t, std::uint32_t> subscription_of_channel_;
  std::map<std::uint32_t, std::deque<DataFrame>> queued_;  ///< by subscription id
  std::uint32_t last_served_{0};
  bool overflowed_{false};
  SessionCounters counters_;
};

}  // namespace navbus::foxglove
