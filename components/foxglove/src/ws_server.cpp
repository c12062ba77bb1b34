#include "navbus/foxglove/ws_server.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

#include <boost/asio.hpp>
#include <boost/beast.hpp>

namespace navbus::foxglove {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;

namespace {

/// Whether a Sec-WebSocket-Protocol header lists the subprotocol (comma-separated tokens).
bool offersSubprotocol(beast::string_view header) {
  std::string list(header);
  std::size_t at = 0;
  while (at <= list.size()) {
    const std::size_t comma = std::min(list.find(',', at), list.size());
    std::string token = list.substr(at, comma - at);
    token.erase(0, token.find_first_not_of(" \t"));
    token.erase(token.find_last_not_of(" \t") + 1);
    if (token == kSubprotocol) return true;
    at = comma + 1;
  }
  return false;
}

void addSession(ServerCounters& out, const SessionCounters& s) {
  out.frames_dropped += s.frames_dropped;
  out.requests_refused += s.requests_refused;
  for (const auto& [channel, n] : s.dropped_by_channel) out.dropped_by_channel[channel] += n;
}

}  // namespace

class WsServer::Impl {
 public:
  class Connection;

  explicit Impl(ServerOptions options) : options_(std::move(options)), acceptor_(io_) {
    boost::system::error_code ec;
    const auto address = net::ip::make_address(options_.bind, ec);
    if (ec) {
      throw std::runtime_error("foxglove bridge: --bind '" + options_.bind +
                               "' is not an IP address: " + ec.message());
    }
    const tcp::endpoint endpoint(address, options_.port);
    acceptor_.open(endpoint.protocol(), ec);
    if (!ec) acceptor_.set_option(net::socket_base::reuse_address(true), ec);
    if (!ec) acceptor_.bind(endpoint, ec);
    if (!ec) acceptor_.listen(net::socket_base::max_listen_connections, ec);
    if (ec) {
      throw std::runtime_error("foxglove bridge: cannot listen on " + options_.bind + ":" +
                               std::to_string(options_.port) + ": " + ec.message());
    }
    session_id_ = std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                                     std::chrono::system_clock::now().time_since_epoch())
                                     .count());
  }

  void start() {
    accept();
    thread_ = std::thread([this] { io_.run(); });
  }

  /// Closes the acceptor and every connection; the I/O thread ends once their operations have
  /// completed (with errors), so no handler outlives the server.
  void stop();

  std::uint16_t port() const { return acceptor_.local_endpoint().port(); }

  void advertise(const Channel& c);
  void unadvertise(std::uint32_t id);
  void publish(std::uint32_t channel_id, std::uint64_t receive_ns, const Payload& payload);
  ServerCounters counters() const;

  // For the connections (each on the I/O thread).
  const ServerOptions& options() const { return options_; }
  std::string greeting() const;
  bool channelExists(std::uint32_t id) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return channels_.count(id) != 0;
  }
  void opened(const std::shared_ptr<Connection>& c);
  void closed(const std::shared_ptr<Connection>& c, bool dropped);
  void refusedHandshake() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++totals_.handshakes_refused;
  }

 private:
  void accept();

  ServerOptions options_;
  net::io_context io_{1};
  tcp::acceptor acceptor_;
  std::thread thread_;
  std::string session_id_;
  mutable std::mutex mutex_;  // channels_, connections_, totals_
  std::map<std::uint32_t, Channel> channels_;
  std::set<std::shared_ptr<Connection>> connections_;
  ServerCounters totals_;           ///< of connections that ended, and server-wide events
  std::deque<ClientReport> ended_;  ///< the last kEndedClientReports clients that ended
};

class WsServer::Impl::Connection : public std::enable_shared_from_this<Connection> {
 public:
  Connection(tcp::socket socket, Impl& server)
      : ws_(std::move(socket)),
        server_(server),
        session_(server.options().frames_per_subscription, server.options().max_texts) {
    beast::error_code ec;
    const tcp::endpoint peer = ws_.next_layer().socket().remote_endpoint(ec);
    if (!ec) peer_ = peer.address().to_string() + ":" + std::to_string(peer.port());
  }

  void run() {
    http::async_read(
        ws_.next_layer(), buffer_, request_,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onRequest(ec); });
  }

  /// From any thread: a channel's message, queued if subscribed, then the writer woken.
  void offer(std::uint32_t channel_id, std::uint64_t receive_ns, const Payload& payload) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!open_ || !session_.offer(channel_id, receive_ns, payload)) return;
    }
    wake();
  }
  void text(std::string message) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!open_) return;
      session_.pushText(std::move(message));
    }
    wake();
  }
  void channelGone(std::uint32_t channel_id) {
    std::lock_guard<std::mutex> lock(mutex_);
    session_.channelGone(channel_id);
  }
  SessionCounters sessionCounters() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return session_.counters();
  }
  std::uint64_t sent() const { return sent_.load(); }
  void setNumber(std::uint64_t n) { number_ = n; }
  /// Its account now; `open` false and `dropped` as given once it ended.
  ClientReport report(bool open, bool dropped) const {
    const SessionCounters s = sessionCounters();
    return ClientReport{number_,           peer_, open, dropped, sent(), s.frames_dropped,
                        s.requests_refused};
  }
  /// Ends the connection (the server stops): pending operations complete with errors.
  void shutdown() {
    net::post(ws_.get_executor(), [self = shared_from_this()] { self->end(false); });
  }

 private:
  void onRequest(beast::error_code ec) {
    if (ec) return;  // the peer went before its request was whole
    const auto protocols = request_[http::field::sec_websocket_protocol];
    if (!websocket::is_upgrade(request_) || !offersSubprotocol(protocols)) {
      server_.refusedHandshake();
      refuse();
      return;
    }
    ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
      res.set(http::field::sec_websocket_protocol, kSubprotocol);
      res.set(http::field::server, "navbus foxglove bridge");
    }));
    ws_.read_message_max(server_.options().max_client_message_bytes);
    beast::error_code ignored;
    auto& socket = ws_.next_layer().socket();
    socket.set_option(
        net::socket_base::send_buffer_size(server_.options().socket_send_buffer_bytes), ignored);
    // Each frame goes out at once: with Nagle's algorithm a small frame after another waits for
    // the client's delayed acknowledgment (40 ms on Linux: p99 36 ms measured before this).
    socket.set_option(tcp::no_delay(true), ignored);
    ws_.async_accept(request_,
                     [self = shared_from_this()](beast::error_code e) { self->onAccept(e); });
  }

  /// Not a WebSocket upgrade offering foxglove.websocket.v1: a 400 that says what is needed.
  void refuse() {
    auto res = std::make_shared<http::response<http::string_body>>(http::status::bad_request,
                                                                   request_.version());
    res->set(http::field::content_type, "text/plain");
    res->body() = std::string(
                      "navbus foxglove bridge: connect with a WebSocket client asking for "
                      "the subprotocol ") +
                  kSubprotocol + "\n";
    res->prepare_payload();
    res->keep_alive(false);
    http::async_write(
        ws_.next_layer(), *res, [self = shared_from_this(), res](beast::error_code, std::size_t) {
          beast::error_code ignored;
          self->ws_.next_layer().socket().shutdown(tcp::socket::shutdown_both, ignored);
        });
  }

  void onAccept(beast::error_code ec) {
    if (ec) {
      server_.refusedHandshake();
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      open_ = true;
      session_.pushText(server_.greeting());
    }
    server_.opened(shared_from_this());  // queues the Advertise of the channels on offer
    wake();
    read();
  }

  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->onRead(ec);
    });
  }

  void onRead(beast::error_code ec) {
    if (ec) {
      end(ec != websocket::error::closed && ec != net::error::eof);
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (ws_.got_text()) {
        session_.handleText(beast::buffers_to_string(buffer_.data()),
                            [this](std::uint32_t id) { return server_.channelExists(id); });
      } else {
        session_.handleBinary();
      }
    }
    buffer_.consume(buffer_.size());
    wake();
    read();
  }

  /// Starts the next write on the I/O thread unless one is under way.
  void wake() {
    net::post(ws_.get_executor(), [self = shared_from_this()] { self->writeNext(); });
  }

  void writeNext() {
    if (writing_) return;
    std::optional<Outgoing> next;
    bool overflowed = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!open_) return;
      overflowed = session_.overflowed();
      if (!overflowed) next = session_.next();
    }
    if (overflowed) {  // it does not read its control messages: it would miss advertisements
      end(true);
      return;
    }
    if (!next) return;
    writing_ = true;
    current_ = std::move(*next);
    if (const auto* text = std::get_if<std::string>(&current_)) {
      ws_.text(true);
      ws_.async_write(net::buffer(*text),
                      [self = shared_from_this()](beast::error_code ec, std::size_t) {
                        self->onWrite(ec, false);
                      });
    } else {
      const auto& frame = std::get<DataFrame>(current_);
      const std::array<net::const_buffer, 2> buffers{net::buffer(frame.header),
                                                     net::buffer(*frame.payload)};
      ws_.binary(true);
      ws_.async_write(buffers, [self = shared_from_this()](beast::error_code ec, std::size_t) {
        self->onWrite(ec, true);
      });
    }
  }

  void onWrite(beast::error_code ec, bool data) {
    writing_ = false;
    current_ = std::string();
    if (ec) {
      end(true);
      return;
    }
    if (data) ++sent_;
    writeNext();
  }

  void end(bool dropped) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!open_) return;
      open_ = false;
    }
    beast::error_code ignored;
    ws_.next_layer().socket().shutdown(tcp::socket::shutdown_both, ignored);
    server_.closed(shared_from_this(), dropped);
  }

  websocket::stream<beast::tcp_stream> ws_;
  Impl& server_;
  beast::flat_buffer buffer_;
  http::request<http::string_body> request_;
  mutable std::mutex mutex_;  // session_, open_
  ClientSession session_;
  bool open_{false};
  bool writing_{false};  // I/O thread only
  Outgoing current_;     // the message being written (its buffers must outlive the write)
  std::atomic<std::uint64_t> sent_{0};
  std::uint64_t number_{0};  // set once, under the server's mutex, before any report
  std::string peer_{"unknown peer"};
};

void WsServer::Impl::stop() {
  net::post(io_, [this] {
    boost::system::error_code ec;
    acceptor_.close(ec);
    std::set<std::shared_ptr<Connection>> clients;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      clients = connections_;
    }
    for (const auto& c : clients) c->shutdown();
  });
  if (thread_.joinable()) thread_.join();
}

std::string WsServer::Impl::greeting() const {
  return serverInfoJson(options_.name, session_id_);
}

void WsServer::Impl::accept() {
  acceptor_.async_accept(net::make_strand(io_), [this](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted || !acceptor_.is_open()) return;
    if (!ec) std::make_shared<Connection>(std::move(socket), *this)->run();
    accept();
  });
}

void WsServer::Impl::opened(const std::shared_ptr<Connection>& c) {
  std::vector<Channel> offered;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    connections_.insert(c);
    ++totals_.clients_accepted;
    c->setNumber(totals_.clients_accepted);
    for (const auto& [id, channel] : channels_) offered.push_back(channel);
  }
  c->text(advertiseJson(offered));
}

void WsServer::Impl::closed(const std::shared_ptr<Connection>& c, bool dropped) {
  const SessionCounters s = c->sessionCounters();
  const ClientReport report = c->report(false, dropped);
  std::lock_guard<std::mutex> lock(mutex_);
  if (connections_.erase(c) == 0) return;
  totals_.frames_sent += c->sent();
  addSession(totals_, s);
  if (dropped) ++totals_.clients_dropped;
  ended_.push_back(report);
  if (ended_.size() > kEndedClientReports) ended_.pop_front();
}

void WsServer::Impl::advertise(const Channel& channel) {
  std::set<std::shared_ptr<Connection>> clients;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    channels_[channel.id] = channel;
    clients = connections_;
  }
  const std::string message = advertiseJson({channel});
  for (const auto& c : clients) c->text(message);
}

void WsServer::Impl::unadvertise(std::uint32_t id) {
  std::set<std::shared_ptr<Connection>> clients;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (channels_.erase(id) == 0) return;
    clients = connections_;
  }
  const std::string message = unadvertiseJson({id});
  for (const auto& c : clients) {
    c->channelGone(id);
    c->text(message);
  }
}

void WsServer::Impl::publish(std::uint32_t channel_id, std::uint64_t receive_ns,
                             const Payload& payload) {
  std::set<std::shared_ptr<Connection>> clients;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    clients = connections_;
  }
  for (const auto& c : clients) c->offer(channel_id, receive_ns, payload);
}

ServerCounters WsServer::Impl::counters() const {
  std::set<std::shared_ptr<Connection>> clients;
  ServerCounters out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    clients = connections_;
    out = totals_;
    out.clients.assign(ended_.begin(), ended_.end());
  }
  out.clients_now = clients.size();
  for (const auto& c : clients) {
    out.frames_sent += c->sent();
    addSession(out, c->sessionCounters());
    out.clients.push_back(c->report(true, false));
  }
  std::sort(out.clients.begin(), out.clients.end(),
            [](const ClientReport& a, const ClientReport& b) { return a.number < b.number; });
  return out;
}

WsServer::WsServer(ServerOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  impl_->start();
}

WsServer::~WsServer() {
  impl_->stop();
}

std::uint16_t WsServer::port() const {
  return impl_->port();
}
void WsServer::advertise(const Channel& channel) {
  impl_->advertise(channel);
}
void WsServer::unadvertise(std::uint32_t channel_id) {
  impl_->unadvertise(channel_id);
}
void WsServer::publish(std::uint32_t channel_id, std::uint64_t receive_time_ns,
                       const Payload& payload) {
  impl_->publish(channel_id, receive_time_ns, payload);
}
ServerCounters WsServer::counters() const {
  return impl_->counters();
}

}  // namespace navbus::foxglove
