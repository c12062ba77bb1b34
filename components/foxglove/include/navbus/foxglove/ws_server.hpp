// The Foxglove bridge's WebSocket server (Boost.Beast): accepts clients that ask for the
// foxglove.websocket.v1 subprotocol, sends each its Server Info and the channels on offer, and
// carries their Subscribe / Unsubscribe (client_session.hpp) and the data frames. One I/O thread;
// advertise(), unadvertise() and publish() may be called from any other thread and never wait
// for a client: a client that reads slowly loses its oldest frames (counted), one that does not
// read its control messages is disconnected.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "navbus/foxglove/client_session.hpp"
#include "navbus/foxglove/protocol.hpp"

namespace navbus::foxglove {

struct ServerOptions {
  std::string bind{"127.0.0.1"};  ///< only this machine, unless told otherwise
  std::uint16_t port{8765};       ///< Foxglove's default; 0: any free port (port() says which)
  std::string name{"navbus"};     ///< the Server Info's name
  std::size_t frames_per_subscription{64};
  std::size_t max_texts{256};
  std::size_t max_client_message_bytes{65536};  ///< larger messages close the connection (1009)
  /// The kernel's send buffer per client: small, so that a slow client's backlog waits in the
  /// bounded queues (oldest dropped first, counted), not in the kernel.
  int socket_send_buffer_bytes{128 * 1024};
};

/// One client's account: what it was sent and what it missed.
struct ClientReport {
  std::uint64_t number{0};  ///< 1, 2, ... in the order the clients connected
  std::string peer;         ///< its address and port
  bool open{true};          ///< still connected
  bool dropped{false};      ///< ended by an error, or for control messages not read
  std::uint64_t frames_sent{0};
  std::uint64_t frames_dropped{0};  ///< the oldest of a full subscription queue
  std::uint64_t requests_refused{0};
};

struct ServerCounters {
  std::uint64_t clients_accepted{0};
  std::uint64_t clients_now{0};
  std::uint64_t handshakes_refused{0};  ///< not a WebSocket upgrade, or without the subprotocol
  std::uint64_t clients_dropped{0};     ///< ended by an error, or for control messages not read
  std::uint64_t frames_sent{0};
  std::uint64_t frames_dropped{0};
  std::map<std::uint32_t, std::uint64_t> dropped_by_channel;
  std::uint64_t requests_refused{0};
  /// The clients connected now, after the last kEndedClientReports that ended, by number.
  std::vector<ClientReport> clients;
};
inline constexpr std::size_t kEndedClientReports = 256;

class WsServer {
 public:
  /// Binds and starts serving. Throws std::runtime_error naming the address and the system's
  /// reason when it cannot bind (the port in use, an address not of this machine).
  explicit WsServer(ServerOptions options);
  ~WsServer();
  WsServer(const WsServer&) = delete;
  WsServer& operator=(const WsServer&) = delete;

  std::uint16_t port() const;
  /// Offers a channel to every client, now and on connection.
  void advertise(const Channel& channel);
  void unadvertise(std::uint32_t channel_id);
  /// One message of a channel to every client subscribed to it.
  void publish(std::uint32_t channel_id, std::uint64_t receive_time_ns, const Payload& payload);
  ServerCounters counters() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace navbus::foxglove
