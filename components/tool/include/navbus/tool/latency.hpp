// `navbus latency`: round-trip latency over the bus with navbus's own message type. One
// process pings (writes navbus/latency/ping at a fixed rate, times the echo), another pongs
// (echoes each ping on navbus/latency/pong at once). Both use the sensor stream profiles, so
// the figure is what an IMU increment costs on the participant profile under test (UDP
// loopback, shared memory, LAN, discovery server, DDS Security). A third role, `imu`, is the
// IMU of a running navbus-filter: increment written -> low-latency output (and deterministic
// solution) received, the end-to-end figure to compare with the raw two hops. `flood` and
// `sink` measure saturation throughput: flood writes as fast as the writer takes samples (a
// reliable KEEP_ALL writer blocks while its history is full) and times them until every one is
// acknowledged; sink takes them and counts gaps in their sequence numbers (lost samples).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "navbus/bus/participant.hpp"

namespace navbus::tool {

struct LatencyOptions {
  std::string role;              ///< "ping", "pong", "imu", "flood" or "sink"
  int samples{2000};             ///< pings timed (after the warm-up)
  int warmup{100};               ///< pings sent first and not timed
  double rate_hz{200.0};         ///< ping rate [Hz] (the navigation IMU rate)
  double match_timeout_s{20.0};  ///< wait this long for the other side
  double pong_duration_s{0.0};   ///< pong: stop after this long (0: at SIGINT/SIGTERM)
  std::string csv;               ///< ping: write each round trip [ns] here if not empty
  std::string writer_profile;    ///< ping, pong, flood: data writer profile (default: sensor)
  std::string reader_profile;    ///< ping, pong, sink: data reader profile (default: sensor)
};

/// What a sink saw: samples taken, samples missing between them (sequence gaps), and the time
/// from the first to the last one taken.
struct SinkCount {
  std::uint64_t taken{0}, missing{0}, out_of_order{0};
  std::uint64_t last_seq{0};
  std::int64_t first_ns{-1}, last_ns{-1};
  /// Counts sample `seq` (the flood numbers from 1) taken at `now_ns`.
  void take(std::uint64_t seq, std::int64_t now_ns);
};

/// Nearest-rank statistics of round-trip times [ns].
struct LatencyStats {
  std::size_t count{0};
  double median_ns{0}, p90_ns{0}, p99_ns{0}, p999_ns{0}, p9999_ns{0}, max_ns{0};
};
LatencyStats latencyStats(std::vector<std::int64_t> round_trips_ns);

/// `navbus latency table`: what it runs (latency_table.cpp).
struct LatencyTableOptions {
  int samples{4000};  ///< timed per row and round (after the warm-up)
  int warmup{200};    ///< sent first and not timed
  double rate_hz{200.0};
  int rounds{1};    ///< the whole table this many times, samples pooled per row
  int cpu_hogs{2};  ///< CPU-bound processes beside the loaded rows
  std::string filter_config{"config/filter_latency.yaml"};
  std::string policy{"fifo"};  ///< the real-time rows' `realtime.policy`
  int priority{20};            ///< and `realtime.priority` (lock_memory: true)
  /// and `realtime.cpus`, for the filter and its IMU source alike; empty: the last core, so that
  /// neither waits for the other's core to wake (on this project's virtual machines a
  /// cross-core wake-up cost the idle median 1.3-1.5x the raw round trip, docs/results.md)
  std::vector<int> cpus;
  bool spread{false};  ///< no `realtime.cpus`: the real-time rows' affinity as inherited
  bool keep{false};    ///< keep the work directory (CSV files, logs)
};

/// Runs the table: child processes on domains from `participant.dds.domain_id` (six of them,
/// per round), with its profile and QoS file. Exit 0 when every row received all its samples
/// (the targets are printed, not enforced); throws when a child fails (the message ends with
/// its log) or wrote a CSV file that is not what it should be (naming the file and line).
int runLatencyTable(const bus::Participant::Options& participant, const LatencyTableOptions& o);

/// Runs one side; returns an exit code (runtime error if the other side never matched or a
/// ping was not echoed).
int runLatencyCommand(const bus::Participant::Options& participant, const LatencyOptions& options,
                      bus::ShutdownSignal& shutdown);

}  // namespace navbus::tool
