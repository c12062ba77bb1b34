// `navbus foxglove`: the bus live in Foxglove. A participant that subscribes to every navbus
// topic and serves it over the Foxglove WebSocket protocol (components/foxglove): a channel per
// topic with the type's schema (OMG IDL, or ROS 2 msg under ROS 2 naming) and the samples' CDR
// bytes, advertised while the topic has a writer; and the channels in Foxglove's own schemas
// derived from them (foxglove_channels.hpp: LocationFix for the Map panel, Log lines). It never
// back-pressures the bus: each client has a bounded queue per channel; what a slow client misses is
// counted in this participant's health (navbus-foxglove, REJECT_CLIENT_BEHIND per topic).
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <memory>
#include <optional>

#include <spdlog/spdlog.h>
#include <fastdds/dds/subscriber/DataReader.hpp>

#include "navbus/bus/app.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/foxglove/schemas.hpp"
#include "navbus/foxglove/ws_server.hpp"
#include "navbus/tool/foxglove_channels.hpp"
#include "navbus/tool/topic_registry.hpp"
#include "subcommand.hpp"

namespace navbus::tool::cli {

namespace {

constexpr const char* kCdr = "cdr";
/// The bridge's default niceness: below the navigation participants (0) for the CPU.
constexpr int kBridgeNiceness = 10;

/// A channel in Foxglove's schemas, advertised while one of its source topics is.
struct DerivedBridged {
  foxglove::Channel channel;
  std::vector<std::string> sources;
  bool advertised{false};
};

/// The topics each derived channel is made from (foxglove_channels.hpp).
std::vector<std::string> derivedSources(DerivedChannel c) {
  if (c == DerivedChannel::kLocationFix) return {bus::topic::kNavSolution};
  return {bus::topic::kFaultDecision, bus::topic::kFilterCommand, bus::topic::kCommandOutcome};
}

/// The bus side of the bridge: samples in, channels and frames out.
class BusBridge final : public SampleSink {
 public:
  BusBridge(foxglove::WsServer& server, bus::HealthCounters& health, bool ros2)
      : server_(server), health_(health), ros2_(ros2) {}

  /// Subscribes to every navbus topic (channel id: its place in the registry), then adds the
  /// derived channels (ids after them).
  void start(bus::Participant& p) {
    for (const auto& e : topicRegistry()) add(p, e);
    const auto schemas = derivedChannelSchemas(ros2_);
    for (std::size_t i = 0; i < kDerivedChannelCount; ++i) {
      DerivedBridged d;
      d.channel.id = static_cast<std::uint32_t>(bridged_.size() + i);
      d.channel.topic = schemas[i].topic;
      d.channel.encoding = foxglove::kJsonEncoding;
      d.channel.schema_name = schemas[i].schema_name;
      d.channel.schema = schemas[i].schema;
      d.channel.schema_encoding = foxglove::kJsonSchemaEncoding;
      d.sources = derivedSources(static_cast<DerivedChannel>(i));
      for (const auto& source : d.sources) bridged_[index_.at(source)].derives = true;
      derived_[i] = d;
    }
  }

  void onSample(const std::string& topic, const SampleTimes& times,
                const SampleViews& sample) override {
    Bridged& b = bridged_[index_.at(topic)];
    if (!b.advertised) return;  // a sample before its writer matched: no channel yet
    ++health_.stream(topic).accepted;
    const std::uint64_t receive_ns =
        times.reception_ns < 0 ? 0 : static_cast<std::uint64_t>(times.reception_ns);
    server_.publish(b.channel.id, receive_ns,
                    std::make_shared<const std::vector<std::uint8_t>>(sample.cdr()));
    if (!b.derives) return;
    std::optional<DerivedMessage> m = sample.derived();
    if (!m) return;
    const DerivedBridged& d = derived_[static_cast<std::size_t>(m->channel)];
    ++health_.stream(d.channel.topic).accepted;
    server_.publish(d.channel.id, receive_ns,
                    std::make_shared<const std::vector<std::uint8_t>>(std::move(m->json)));
  }

  /// Samples the bridge's own readers missed, over every topic.
  std::uint64_t samplesLost() const { return lost_total_; }

  /// Advertises the channels whose topics gained a writer, withdraws those that lost their last
  /// one, and puts the clients' drops into the health counters.
  void update() {
    for (Bridged& b : bridged_) {
      eprosima::fastdds::dds::SampleLostStatus lost;
      b.reader->get_sample_lost_status(lost);
      const auto lost_now = static_cast<std::uint64_t>(lost.total_count);
      health_.stream(b.name).sequence_gaps += lost_now - b.lost;
      lost_total_ += lost_now - b.lost;
      b.lost = lost_now;
      eprosima::fastdds::dds::SubscriptionMatchedStatus status;
      b.reader->get_subscription_matched_status(status);
      const bool has_writer = status.current_count > 0;
      if (has_writer == b.advertised) continue;
      b.advertised = has_writer;
      advertised(b.channel, has_writer, status.current_count);
    }
    for (DerivedBridged& d : derived_) {
      const bool any = std::any_of(d.sources.begin(), d.sources.end(), [this](const auto& s) {
        return bridged_[index_.at(s)].advertised;
      });
      if (any == d.advertised) continue;
      d.advertised = any;
      advertised(d.channel, any, -1);
    }
    const foxglove::ServerCounters c = server_.counters();
    for (const auto& [channel, dropped] : c.dropped_by_channel) {
      health_.stream(topicOfChannel(channel)).rejected[navbus::REJECT_CLIENT_BEHIND] = dropped;
    }
    for (const foxglove::ClientReport& r : c.clients) {
      if (r.open || r.number <= last_ended_logged_) continue;
      logClient(r);
      last_ended_logged_ = r.number;
    }
  }

  /// What one client was sent and missed.
  static void logClient(const foxglove::ClientReport& r) {
    spdlog::info(
        "client {} ({}) {}: frames sent {}, dropped for being behind {}, requests refused {}",
        r.number, r.peer,
        r.open ? "connected"
               : (r.dropped ? "ended by an error or an unread control queue" : "ended"),
        r.frames_sent, r.frames_dropped, r.requests_refused);
  }

 private:
  struct Bridged {
    foxglove::Channel channel;
    std::string name;
    eprosima::fastdds::dds::DataReader* reader{nullptr};
    bool advertised{false};
    bool derives{false};    ///< a source of a derived channel
    std::uint64_t lost{0};  ///< samples its best-effort reader missed (DDS sample-lost status)
  };

  void add(bus::Participant& p, const TopicEntry& e) {
    Bridged b;
    b.channel.id = static_cast<std::uint32_t>(bridged_.size());
    const TopicSchema t = topicSchema(e, ros2_);
    b.channel.topic = t.channel_topic;
    b.channel.encoding = kCdr;
    b.channel.schema_name = t.schema_name;
    b.channel.schema = t.schema;
    b.channel.schema_encoding = t.schema_encoding;
    b.name = e.name;
    index_[e.name] = bridged_.size();
    bridged_.push_back(b);
    bridged_.back().reader = e.subscribe_with(p, *this, bridgeReaderProfile(e));
  }

  /// Decisions, commands and outcomes are read as their own durable reliable readers read them
  /// (rare; the Log channel wants each one); every other stream best effort, so that a bridge
  /// short of CPU never holds back a reliable writer.
  static std::string bridgeReaderProfile(const TopicEntry& e) {
    return e.reader_profile == bus::profile::kDecisionReader ? e.reader_profile
                                                             : bus::profile::kFoxgloveReader;
  }

  void advertised(const foxglove::Channel& channel, bool on, int writers) {
    if (on) {
      server_.advertise(channel);
    } else {
      server_.unadvertise(channel.id);
    }
    if (writers < 0) {
      spdlog::info("{}: {} (derived)", channel.topic, on ? "advertised" : "withdrawn");
    } else {
      spdlog::info("{}: {} ({} writer(s))", channel.topic, on ? "advertised" : "withdrawn",
                   writers);
    }
  }

  const std::string& topicOfChannel(std::uint32_t channel) const {
    return channel < bridged_.size() ? bridged_[channel].name
                                     : derived_.at(channel - bridged_.size()).channel.topic;
  }

  foxglove::WsServer& server_;
  bus::HealthCounters& health_;
  bool ros2_;
  std::vector<Bridged> bridged_;
  std::array<DerivedBridged, kDerivedChannelCount> derived_;
  std::uint64_t lost_total_{0};
  std::uint64_t last_ended_logged_{0};
  std::map<std::string, std::size_t> index_;
};

class FoxgloveCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "foxglove",
        "serve the bus live to Foxglove over its WebSocket protocol (foxglove.websocket.v1): "
        "open ws://HOST:PORT in Foxglove's 'Foxglove WebSocket' connection");
    cli_->add_option("--port", options_.port, "TCP port (Foxglove's default 8765; 0: any free)")
        ->check(CLI::Range(0, 65535));
    cli_->add_option("--bind", options_.bind,
                     "address to listen on (default this machine only; 0.0.0.0: every interface)");
    cli_->add_option("--queue", options_.frames_per_subscription,
                     "frames waiting per client and channel; beyond it the oldest is dropped and "
                     "counted")
        ->check(CLI::Range(1, 100000));
    cli_->add_option("--duration", duration_s_, "stop after this many seconds (0: until SIGINT)")
        ->check(CLI::Range(0.0, 1e7));
    cli_->add_option("--nice", nice_,
                     "the bridge's CPU niceness (0-19): a live view yields the CPU to the "
                     "navigation participants")
        ->check(CLI::Range(0, 19));
  }

  int run(bus::Participant::Options& options, bus::ShutdownSignal& shutdown) override {
    // Before any thread exists: Linux keeps a niceness per thread, and new threads inherit it.
    if (setpriority(PRIO_PROCESS, 0, nice_) != 0) {
      spdlog::warn("--nice {}: {}", nice_, std::strerror(errno));
    }
    options.dds.name = "navbus-foxglove";
    options.publish_health = true;  // a service on the bus: its drops are reported
    foxglove::WsServer server(options_);
    spdlog::info("Foxglove WebSocket server on ws://{}:{} ({})", options_.bind, server.port(),
                 foxglove::kSubprotocol);
    bus::Participant p(options, shutdown);
    BusBridge bridge(server, p.health(), options.dds.ros2_names);
    bridge.start(p);
    p.setState(navbus::STATE_RUNNING);
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s_);
    while (!p.stopping() && (duration_s_ <= 0.0 || std::chrono::steady_clock::now() < end)) {
      p.spinOnce(std::chrono::milliseconds(50));
      bridge.update();
    }
    bridge.update();
    p.finish();
    const foxglove::ServerCounters c = server.counters();
    for (const foxglove::ClientReport& r : c.clients) {
      if (r.open) BusBridge::logClient(r);
    }
    spdlog::info(
        "foxglove bridge: clients accepted {} (now {}, ended by an error or an unread control "
        "queue {}), handshakes refused {}, frames sent {}, dropped for clients behind {}, "
        "requests refused {}; samples the bridge's best-effort readers missed {}",
        c.clients_accepted, c.clients_now, c.clients_dropped, c.handshakes_refused, c.frames_sent,
        c.frames_dropped, c.requests_refused, bridge.samplesLost());
    return bus::kExitOk;
  }

 private:
  foxglove::ServerOptions options_;
  double duration_s_{0.0};
  int nice_{kBridgeNiceness};
};

}  // namespace

void addFoxgloveSubcommand(Subcommands& out) {
  out.push_back(std::make_unique<FoxgloveCommand>());
}

}  // namespace navbus::tool::cli
