#include "latency.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>

#include <navbus_idl/ImuPubSubTypes.h>

#include "navbus/bus/app.hpp"
#include "navbus/bus/topics.hpp"

namespace navbus::tool {

namespace {

using Clock = std::chrono::steady_clock;

std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

bool spinUntil(bus::Participant& p, double timeout_s, const std::function<bool()>& done) {
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (!done() && !p.stopping() && Clock::now() < end) p.spinOnce(std::chrono::milliseconds(5));
  return done();
}

std::size_t matchedWriters(eprosima::fastdds::dds::DataReader* reader) {
  eprosima::fastdds::dds::SubscriptionMatchedStatus status;
  reader->get_subscription_matched_status(status);
  return static_cast<std::size_t>(status.current_count);
}

int runPong(bus::Participant& p, const LatencyOptions& o) {
  auto pong =
      p.createWriter<ImuIncrementPubSubType>(bus::topic::kLatencyPong, bus::profile::kSensorWriter);
  std::uint64_t echoed = 0;
  p.subscribe<ImuIncrementPubSubType>(bus::topic::kLatencyPing, bus::profile::kSensorReader,
                                      [&](const ImuIncrement& s, const auto&) {
                                        if (pong.write(s)) ++echoed;
                                      });
  spinUntil(p, o.pong_duration_s > 0 ? o.pong_duration_s : 1e9, [] { return false; });
  spdlog::info("pong: echoed {} pings", echoed);
  p.finish();
  return bus::kExitOk;
}

void printStats(const LatencyStats& s, std::uint64_t lost, std::size_t sent, double elapsed_s) {
  const auto us = [](double ns) { return ns / 1000.0; };
  std::printf("round trip [us]  median %.1f  p90 %.1f  p99 %.1f  p99.9 %.1f  max %.1f\n",
              us(s.median_ns), us(s.p90_ns), us(s.p99_ns), us(s.p999_ns), us(s.max_ns));
  std::printf(
      "one way [us]     median %.1f  p90 %.1f  p99 %.1f  p99.9 %.1f  max %.1f"
      "  (half the round trip)\n",
      us(s.median_ns / 2), us(s.p90_ns / 2), us(s.p99_ns / 2), us(s.p999_ns / 2), us(s.max_ns / 2));
  std::printf("pings timed %zu, not echoed %llu; %zu sent at %.1f pings/s\n", s.count,
              static_cast<unsigned long long>(lost), sent,
              elapsed_s > 0 ? static_cast<double>(sent) / elapsed_s : 0.0);
}

int runPing(bus::Participant& p, const LatencyOptions& o) {
  auto ping =
      p.createWriter<ImuIncrementPubSubType>(bus::topic::kLatencyPing, bus::profile::kSensorWriter);
  const std::size_t total = static_cast<std::size_t>(o.warmup + o.samples);
  std::vector<std::int64_t> sent_ns(total, 0), rtt_ns(total, -1);
  auto* reader =
      p.subscribe<ImuIncrementPubSubType>(bus::topic::kLatencyPong, bus::profile::kSensorReader,
                                          [&](const ImuIncrement& s, const auto&) {
                                            const std::size_t k = s.seq();
                                            if (k < total && rtt_ns[k] < 0 && sent_ns[k] > 0)
                                              rtt_ns[k] = nowNs() - sent_ns[k];
                                          });
  if (!spinUntil(p, o.match_timeout_s,
                 [&] { return ping.matchedReaders() > 0 && matchedWriters(reader) > 0; })) {
    spdlog::error(
        "no pong matched within {} s (run `navbus latency pong` with the same domain, "
        "profile and QoS file)",
        o.match_timeout_s);
    return bus::kExitRuntimeError;
  }
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / o.rate_hz));
  ImuIncrement s;
  s.sensor_id(1);
  auto next = Clock::now();
  const auto start = next;
  for (std::size_t k = 0; k < total && !p.stopping(); ++k) {
    while (Clock::now() < next) p.spinOnce(next - Clock::now());
    s.seq(k);
    sent_ns[k] = nowNs();
    ping.write(s);
    next += period;
  }
  spinUntil(p, 2.0, [&] { return rtt_ns.back() >= 0; });
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  std::vector<std::int64_t> timed(rtt_ns.begin() + o.warmup, rtt_ns.end());
  const auto lost = static_cast<std::uint64_t>(
      std::count_if(timed.begin(), timed.end(), [](std::int64_t v) { return v < 0; }));
  timed.erase(std::remove_if(timed.begin(), timed.end(), [](std::int64_t v) { return v < 0; }),
              timed.end());
  if (!o.csv.empty()) {
    std::ofstream csv(o.csv);
    csv << "round_trip_ns\n";
    for (const auto v : timed) csv << v << '\n';
  }
  printStats(latencyStats(timed), lost, total, elapsed_s);
  p.finish();
  return lost == 0 ? bus::kExitOk : bus::kExitRuntimeError;
}

}  // namespace

LatencyStats latencyStats(std::vector<std::int64_t> v) {
  LatencyStats s;
  s.count = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const auto rank = [&](double q) {  // nearest rank
    const auto i = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
    return static_cast<double>(v[std::clamp<std::size_t>(i, 1, v.size()) - 1]);
  };
  s.median_ns = rank(0.5);
  s.p90_ns = rank(0.9);
  s.p99_ns = rank(0.99);
  s.p999_ns = rank(0.999);
  s.max_ns = static_cast<double>(v.back());
  return s;
}

int runLatencyCommand(const bus::Participant::Options& participant, const LatencyOptions& o,
                      bus::ShutdownSignal& shutdown) {
  bus::Participant p(participant, shutdown);
  return o.role == "pong" ? runPong(p, o) : runPing(p, o);
}

}  // namespace navbus::tool
