#include "navbus/tool/latency.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <unordered_map>
#include <utility>

#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "navbus/bus/app.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/tool/spin.hpp"

namespace navbus::tool {

namespace {

using Clock = std::chrono::steady_clock;

std::int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

/// This host's system clock: the clock of DDS source time stamps.
std::int64_t systemNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::size_t matchedWriters(eprosima::fastdds::dds::DataReader* reader) {
  eprosima::fastdds::dds::SubscriptionMatchedStatus status;
  reader->get_subscription_matched_status(status);
  return static_cast<std::size_t>(status.current_count);
}

std::string writerProfile(const LatencyOptions& o) {
  return o.writer_profile.empty() ? bus::profile::kSensorWriter : o.writer_profile;
}
std::string readerProfile(const LatencyOptions& o) {
  return o.reader_profile.empty() ? bus::profile::kSensorReader : o.reader_profile;
}

int runPong(bus::Participant& p, const LatencyOptions& o) {
  auto pong = p.createWriter<ImuIncrementPubSubType>(bus::topic::kLatencyPong, writerProfile(o));
  std::uint64_t echoed = 0;
  p.subscribe<ImuIncrementPubSubType>(bus::topic::kLatencyPing, readerProfile(o),
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
  auto ping = p.createWriter<ImuIncrementPubSubType>(bus::topic::kLatencyPing, writerProfile(o));
  const std::size_t total = static_cast<std::size_t>(o.warmup + o.samples);
  std::vector<std::int64_t> sent_ns(total, 0), rtt_ns(total, -1);
  auto* reader = p.subscribe<ImuIncrementPubSubType>(
      bus::topic::kLatencyPong, readerProfile(o), [&](const ImuIncrement& s, const auto&) {
        const std::size_t k = s.seq();
        if (k < total && rtt_ns[k] < 0 && sent_ns[k] > 0) rtt_ns[k] = nowNs() - sent_ns[k];
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

void printOneWay(const char* what, const LatencyStats& s, std::size_t expected) {
  const auto us = [](double ns) { return ns / 1000.0; };
  std::printf("%-34s median %8.1f  p90 %8.1f  p99 %8.1f  p99.9 %8.1f  max %9.1f  (%zu of %zu)\n",
              what, us(s.median_ns), us(s.p90_ns), us(s.p99_ns), us(s.p999_ns), us(s.max_ns),
              s.count, expected);
}

/// The increment of a body at rest, level, x north, at `lat_rad` (specific force against
/// gravity, the Earth rate), over `dt_s`.
core::ImuIncrement restingIncrement(double lat_rad, double height_m, double dt_s) {
  core::ImuIncrement inc;
  inc.interval_s = dt_s;
  inc.delta_vel_b_mps = -core::earth::gravityNed(lat_rad, height_m) * dt_s;
  inc.delta_angle_b_rad = core::earth::omegaIeNed(lat_rad) * dt_s;
  return inc;
}

/// End to end: this process is the IMU of a running navbus-filter (sensor 1 at --rate, time
/// stamps from the system clock's GPS-like count) and times each increment from its write to
/// the reception of the low-latency output of the same time, and of the deterministic
/// solution where one has that time.
int runImuSource(bus::Participant& p, const LatencyOptions& o) {
  auto imu = p.createWriter<ImuIncrementPubSubType>(bus::topic::kImuIncrement, writerProfile(o));
  const std::size_t total = static_cast<std::size_t>(o.warmup + o.samples);
  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / o.rate_hz));
  // Data time of increment k: t0 + (k + 1) period; its write time is kept by k.
  const std::int64_t t0 = (std::chrono::duration_cast<std::chrono::nanoseconds>(
                               std::chrono::system_clock::now().time_since_epoch())
                               .count() /
                           period_ns) *
                          period_ns;
  std::vector<std::int64_t> sent_ns(total, 0), fast_ns(total, -1), solution_ns(total, -1);
  // The filter's write time (the output's DDS source time stamp, system clock: same host)
  // splits the low-latency path into hop 1 + the filter, and hop 2.
  std::vector<std::int64_t> sent_system_ns(total, 0), fast_written_ns(total, -1);
  const auto index = [&](std::uint64_t time_gps_ns) -> std::int64_t {
    const std::int64_t k = (static_cast<std::int64_t>(time_gps_ns) - t0) / period_ns - 1;
    return k >= 0 && static_cast<std::size_t>(k) < total &&
                   t0 + (k + 1) * period_ns == static_cast<std::int64_t>(time_gps_ns)
               ? k
               : -1;
  };
  const auto receiver = [&](std::vector<std::int64_t>& into, std::vector<std::int64_t>* written) {
    return [&, into_ptr = &into, written](const NavigationSolution& s, const auto& info) {
      const std::int64_t k = index(s.time_gps_ns());
      if (k < 0) return;
      const auto i = static_cast<std::size_t>(k);
      if ((*into_ptr)[i] >= 0 || sent_ns[i] <= 0) return;
      (*into_ptr)[i] = nowNs() - sent_ns[i];
      if (written) (*written)[i] = info.source_timestamp.to_ns() - sent_system_ns[i];
    };
  };
  auto* fast = p.subscribe<NavigationSolutionPubSubType>(bus::topic::kNavSolutionLowLatency,
                                                         bus::profile::kLowLatencySolutionReader,
                                                         receiver(fast_ns, &fast_written_ns));
  auto* det = p.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader, receiver(solution_ns, nullptr));
  if (!spinUntil(p, o.match_timeout_s, [&] {
        return imu.matchedReaders() > 0 && matchedWriters(fast) > 0 && matchedWriters(det) > 0;
      })) {
    spdlog::error(
        "no navbus-filter with the low-latency output matched within {} s (run navbus-filter "
        "with config/filter_latency.yaml, or any configuration with low_latency_output.enabled "
        "and this IMU: sensor 1 at --rate, same domain, profile and QoS file)",
        o.match_timeout_s);
    return bus::kExitRuntimeError;
  }
  const double lat = 36.5 * M_PI / 180.0, height = 100.0;  // config/filter_latency.yaml
  core::ImuIncrement inc = restingIncrement(lat, height, 1e-9 * static_cast<double>(period_ns));
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::nanoseconds(period_ns));
  auto next = Clock::now();
  const auto start = next;
  for (std::size_t k = 0; k < total && !p.stopping(); ++k) {
    while (Clock::now() < next) p.spinOnce(next - Clock::now());
    inc.time_ns = t0 + static_cast<std::int64_t>(k + 1) * period_ns;
    const ImuIncrement msg = bus::toIdl(inc, 1, k + 1);
    sent_system_ns[k] = systemNowNs();
    sent_ns[k] = nowNs();
    imu.write(msg);
    next += period;
  }
  spinUntil(p, 2.0, [&] { return fast_ns.back() >= 0; });
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  const auto timed = [&](const std::vector<std::int64_t>& v) {
    std::vector<std::int64_t> out;
    for (std::size_t k = static_cast<std::size_t>(o.warmup); k < v.size(); ++k)
      if (v[k] >= 0) out.push_back(v[k]);
    return out;
  };
  const std::vector<std::int64_t> fast_t = timed(fast_ns), det_t = timed(solution_ns);
  const std::size_t solutions_expected = static_cast<std::size_t>(std::count_if(
      solution_ns.begin() + o.warmup, solution_ns.end(), [](std::int64_t v) { return v >= 0; }));
  std::printf("IMU written -> received [us], %zu increments at %.1f Hz over %.1f s:\n",
              static_cast<std::size_t>(o.samples), o.rate_hz, elapsed_s);
  printOneWay("low-latency output", latencyStats(fast_t), static_cast<std::size_t>(o.samples));
  std::vector<std::int64_t> hop1, hop2;  // where both are known
  for (std::size_t k = static_cast<std::size_t>(o.warmup); k < total; ++k) {
    if (fast_ns[k] < 0 || fast_written_ns[k] < 0) continue;
    hop1.push_back(fast_written_ns[k]);
    hop2.push_back(fast_ns[k] - fast_written_ns[k]);
  }
  printOneWay("  increment -> filter's write", latencyStats(hop1), fast_t.size());
  printOneWay("  filter's write -> received", latencyStats(hop2), fast_t.size());
  printOneWay("deterministic solution", latencyStats(det_t), solutions_expected);
  if (!o.csv.empty()) {
    std::ofstream csv(o.csv);
    csv << "seq,low_latency_ns,solution_ns\n";
    for (std::size_t k = static_cast<std::size_t>(o.warmup); k < total; ++k)
      csv << k + 1 << ',' << fast_ns[k] << ',' << solution_ns[k] << '\n';
  }
  p.finish();
  return fast_t.size() == static_cast<std::size_t>(o.samples) ? bus::kExitOk
                                                              : bus::kExitRuntimeError;
}

/// Writes `count` samples numbered from `first_seq` as fast as the writer takes them (a write
/// that times out on a full history is retried); returns the retries, or -1 if stopped.
std::int64_t writeAsFastAsPossible(bus::Participant& p, bus::Writer<ImuIncrement>& writer,
                                   std::uint64_t first_seq, std::size_t count) {
  ImuIncrement s;
  s.sensor_id(1);
  s.interval_ns(5'000'000);
  std::int64_t retries = 0;
  for (std::size_t k = 0; k < count; ++k) {
    s.seq(first_seq + k);
    while (!writer.raw()->write(&s)) {
      if (p.stopping()) return -1;
      ++retries;
    }
  }
  return retries;
}

/// Saturation: --warmup samples, then --samples timed from the first write until every one is
/// acknowledged (a reliable writer; a best-effort one counts them sent); disposes the instance
/// at the end so that the sink stops.
int runFlood(bus::Participant& p, const LatencyOptions& o) {
  auto flood = p.createWriter<ImuIncrementPubSubType>(bus::topic::kLatencyPing, writerProfile(o));
  if (!spinUntil(p, o.match_timeout_s, [&] { return flood.matchedReaders() > 0; })) {
    spdlog::error(
        "no sink matched within {} s (run `navbus latency sink` with the same domain, profile "
        "and QoS file)",
        o.match_timeout_s);
    return bus::kExitRuntimeError;
  }
  const eprosima::fastrtps::Duration_t ack_timeout(30, 0);
  const auto warmup = static_cast<std::size_t>(o.warmup);
  if (writeAsFastAsPossible(p, flood, 1, warmup) < 0) return bus::kExitRuntimeError;
  flood.raw()->wait_for_acknowledgments(ack_timeout);
  const auto start = Clock::now();
  const std::int64_t retries =
      writeAsFastAsPossible(p, flood, warmup + 1, static_cast<std::size_t>(o.samples));
  if (retries < 0) return bus::kExitRuntimeError;
  const bool acknowledged =
      flood.raw()->wait_for_acknowledgments(ack_timeout) == ReturnCode_t::RETCODE_OK;
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  ImuIncrement key;
  key.sensor_id(1);
  flood.dispose(key);
  ImuIncrementPubSubType type;
  const double bytes = type.getSerializedSizeProvider(&key)();
  const double rate = static_cast<double>(o.samples) / elapsed_s;
  std::printf(
      "flood: %d samples of %.0f bytes written%s in %.3f s: %.0f samples/s, %.2f MB/s; "
      "write retries %lld\n",
      o.samples, bytes, acknowledged ? " and acknowledged" : " (NOT all acknowledged)", elapsed_s,
      rate, rate * bytes * 1e-6, static_cast<long long>(retries));
  flood.raw()->wait_for_acknowledgments(ack_timeout);  // the dispose
  p.finish();
  return acknowledged ? bus::kExitOk : bus::kExitRuntimeError;
}

/// Counts what a flood sends until the flood disposes its instance (or --duration passes);
/// exit 1 if a sample was missing or none came.
int runSink(bus::Participant& p, const LatencyOptions& o) {
  SinkCount count;
  bool ended = false;
  bus::ReaderCallbacks callbacks;
  callbacks.on_disposed = [&](const auto&) { ended = true; };
  p.subscribe<ImuIncrementPubSubType>(
      bus::topic::kLatencyPing, readerProfile(o),
      [&](const ImuIncrement& s, const auto&) { count.take(s.seq(), nowNs()); }, callbacks);
  spinUntil(p, o.pong_duration_s > 0 ? o.pong_duration_s : 1e9, [&] { return ended; });
  const double span_s =
      count.taken > 1 ? 1e-9 * static_cast<double>(count.last_ns - count.first_ns) : 0.0;
  std::printf(
      "sink: took %llu samples in %.3f s (first to last): %.0f samples/s; missing %llu "
      "(sequence gaps), out of order %llu; %s\n",
      static_cast<unsigned long long>(count.taken), span_s,
      span_s > 0 ? static_cast<double>(count.taken - 1) / span_s : 0.0,
      static_cast<unsigned long long>(count.missing),
      static_cast<unsigned long long>(count.out_of_order),
      ended ? "the flood ended its stream" : "stopped before the flood ended its stream");
  p.finish();
  return count.taken > 0 && count.missing == 0 ? bus::kExitOk : bus::kExitRuntimeError;
}

/// Passive end to end, against running participants (for example navbus-sensor-sim in real
/// time, navbus-filter with the low-latency output, the fault manager): each IMU increment's
/// source time stamp (the writer's system clock at its write, from the DDS sample info) to the
/// reception of the low-latency output and of the deterministic solution of the same data time.
/// Same host: both clocks are this host's system clock. Stops after --samples outputs or
/// --duration seconds.
int runObserve(bus::Participant& p, const LatencyOptions& o) {
  std::unordered_map<std::uint64_t, std::int64_t> imu_written_ns, fast_rx_ns, det_rx_ns;
  // Best effort (the watchdog profile): observing never back-pressures the sensor.
  p.subscribe<ImuIncrementPubSubType>(
      bus::topic::kImuIncrement, bus::profile::kSensorWatchdogReader,
      [&](const ImuIncrement& m, const eprosima::fastdds::dds::SampleInfo& info) {
        imu_written_ns.emplace(m.time_gps_ns(), info.source_timestamp.to_ns());
      });
  const auto receiver = [&](std::unordered_map<std::uint64_t, std::int64_t>& into) {
    return [&, into_ptr = &into](const NavigationSolution& s, const auto&) {
      into_ptr->emplace(s.time_gps_ns(), systemNowNs());
    };
  };
  p.subscribe<NavigationSolutionPubSubType>(bus::topic::kNavSolutionLowLatency,
                                            bus::profile::kLowLatencySolutionReader,
                                            receiver(fast_rx_ns));
  p.subscribe<NavigationSolutionPubSubType>(bus::topic::kNavSolution, bus::profile::kSolutionReader,
                                            receiver(det_rx_ns));
  const auto total = static_cast<std::size_t>(o.warmup + o.samples);
  spinUntil(p, o.pong_duration_s > 0 ? o.pong_duration_s : 1e9,
            [&] { return fast_rx_ns.size() >= total; });
  // Latencies of the outputs whose increment was seen, from the data time of the first output
  // after the --warmup first ones.
  std::vector<std::uint64_t> output_times;
  for (const auto& entry : fast_rx_ns) output_times.push_back(entry.first);
  std::sort(output_times.begin(), output_times.end());
  const std::uint64_t from =
      output_times.empty()
          ? 0
          : output_times[std::min(output_times.size() - 1, static_cast<std::size_t>(o.warmup))];
  const auto latencies = [&](const std::unordered_map<std::uint64_t, std::int64_t>& rx) {
    std::vector<std::int64_t> out;
    for (const auto& [time, received_ns] : rx) {
      const auto it = imu_written_ns.find(time);
      if (time >= from && it != imu_written_ns.end()) out.push_back(received_ns - it->second);
    }
    return out;
  };
  const std::vector<std::int64_t> fast = latencies(fast_rx_ns), det = latencies(det_rx_ns);
  std::printf("IMU written (source time stamp) -> received [us], %zu increments seen:\n",
              imu_written_ns.size());
  printOneWay("low-latency output", latencyStats(fast), fast_rx_ns.size());
  printOneWay("deterministic solution", latencyStats(det), det_rx_ns.size());
  if (!o.csv.empty()) {
    std::ofstream csv(o.csv);
    csv << "output,latency_ns\n";
    for (const auto v : fast) csv << "low_latency," << v << '\n';
    for (const auto v : det) csv << "solution," << v << '\n';
  }
  p.finish();
  return fast.empty() ? bus::kExitRuntimeError : bus::kExitOk;
}

}  // namespace

void SinkCount::take(std::uint64_t seq, std::int64_t now_ns) {
  if (first_ns < 0) first_ns = now_ns;
  last_ns = now_ns;
  ++taken;
  if (seq <= last_seq) {
    ++out_of_order;
    return;
  }
  missing += seq - last_seq - 1;
  last_seq = seq;
}

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
  s.p9999_ns = rank(0.9999);
  s.max_ns = static_cast<double>(v.back());
  return s;
}

int runLatencyCommand(const bus::Participant::Options& participant, const LatencyOptions& o,
                      bus::ShutdownSignal& shutdown) {
  bus::Participant p(participant, shutdown);
  if (o.role == "pong") return runPong(p, o);
  if (o.role == "imu") return runImuSource(p, o);
  if (o.role == "flood") return runFlood(p, o);
  if (o.role == "sink") return runSink(p, o);
  if (o.role == "observe") return runObserve(p, o);
  return runPing(p, o);
}

}  // namespace navbus::tool
