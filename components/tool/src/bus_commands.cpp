// `navbus replay`, `health`, `command` and `latency`: the tool's subcommands that write to the
// bus (navbus_tool_commands runs them).
#include "navbus/bus/app.hpp"
#include "navbus/tool/command.hpp"
#include "navbus/tool/health_check.hpp"
#include "navbus/tool/latency.hpp"
#include "navbus/tool/replay.hpp"
#include "subcommand.hpp"

namespace navbus::tool::cli {
namespace {

class ReplayCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "replay",
        "publish a `navbus record` recording's sensor topics back onto the bus, content unchanged, "
        "paced by their data times (or the recorded source time stamps) scaled by --speed; the "
        "streams are disposed at the end");
    cli_->add_option("recording", replay.recording,
                     "the recording: its directory of CSV files, or its MCAP file")
        ->required()
        ->check(CLI::ExistingPath);
    cli_->add_option("--speed", replay.speed, "1: as recorded, 10: ten times faster, 0: no pacing")
        ->check(CLI::Range(0.0, 1e6));
    cli_->add_option("--pace", replay.pace,
                     "data: by the samples' data times; source: by the recorded DDS source time "
                     "stamps (the bus timing of the recording)")
        ->check(CLI::IsMember({"data", "source"}));
    cli_->add_option("--topics", replay.topics,
                     "only these topics (default: every sensor topic recorded)");
    cli_->add_option("--min-readers", replay.min_readers,
                     "TOPIC=N: wait for N readers of TOPIC before the first sample (default "
                     "1 each), e.g. navbus/imu/increment_block=2 for a filter and a fault "
                     "manager");
    cli_->add_option("--match-timeout", replay.match_timeout_s,
                     "seconds to wait for a reader of every replayed topic")
        ->check(CLI::Range(0.1, 600.0));
  }
  int run(bus::Participant::Options& options, bus::ShutdownSignal& shutdown) override {
    options.dds.name = "navbus-replay";
    return runReplayCommand(options, replay, shutdown);
  }

 private:
  ReplayOptions replay;
};

class HealthCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "health",
        "exit 0 if PARTICIPANT's own health reports say RUNNING or DEGRADED within --timeout, 1 "
        "otherwise (no report, STARTING, STOPPING); for container healthchecks and scripts");
    cli_->add_option("participant", health.participant, "e.g. navbus-filter")->required();
    cli_->add_option("--timeout", health.timeout_s, "seconds to wait for a working report")
        ->check(CLI::Range(0.1, 600.0));
  }
  int run(bus::Participant::Options& options, bus::ShutdownSignal& shutdown) override {
    options.dds.name = "navbus-health";
    return runHealthCommand(options, health, shutdown);
  }

 private:
  HealthCheckOptions health;
};

class CommandCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "command",
        "send one FilterCommand to navbus-filter and wait for its acknowledgment (enums by name, "
        "with or without their IDL prefix; units as in idl/Fault.idl)");
    cli_->add_option("kind", command.kind,
                     "EXCLUDE_SATELLITE, READMIT_SATELLITE, COMPENSATE_BIAS, SELECT_FUSION, "
                     "SELECT_MODE, RESET, EXCLUDE_STREAM, READMIT_STREAM, FAIL_SENSOR_AXIS, "
                     "RESTORE_SENSOR_AXIS, RELEARN_BIAS, SUSPECT_SENSOR_AXIS")
        ->required();
    cli_->add_option("--vehicle", command.vehicle_id, "vehicle_id of the filter addressed");
    cli_->add_option("--sv", command.sv_id, "GPS PRN (satellite commands)");
    cli_->add_option("--scope", command.scope, "ALL, PSEUDORANGE or PSEUDORANGE_RATE");
    cli_->add_option("--sensor", command.sensor,
                     "ACCELEROMETER or GYRO (bias and axis commands); IMU_STREAM, "
                     "GNSS_OBS_STREAM, ... (stream commands)");
    cli_->add_option("--sensor-id", command.sensor_id, "the stream's sensor id");
    cli_->add_option("--axis", command.axis, "body axis 0, 1 or 2");
    cli_->add_option("--bias", command.bias, "bias to compensate [m/s^2 or rad/s, body]");
    cli_->add_option("--bias-sigma", command.bias_sigma, "its 1-sigma [m/s^2 or rad/s]");
    cli_->add_option("--fusion", command.fusion, "CENTRALIZED, FEDERATED or ADAPTIVE");
    cli_->add_option("--mode", command.mode, "a FilterMode, e.g. TIGHTLY_COUPLED");
    cli_->add_option("--time-gps-ns", command.time_gps_ns,
                     "data time the command refers to [ns, GPS time] (0: at once)");
    cli_->add_option("--onset-gps-ns", command.onset_time_gps_ns,
                     "estimated onset of the fault it answers [ns, GPS time]");
    cli_->add_option("--decision-id", command.decision_id, "the decision it follows (0: none)");
    cli_->add_option("--issuer", command.issuer, "issuer (the filter obeys configured ones)");
    cli_->add_option("--command-id", command.command_id,
                     "unique per issuer, increasing (default: this run's start time [ns])");
    cli_->add_option("--match-timeout", command.match_timeout_s,
                     "seconds to wait for the filter's reader, then for its answer")
        ->check(CLI::Range(0.1, 600.0));
    cli_->add_option("--min-readers", command.min_readers,
                     "write once this many readers of navbus/filter/command matched (the filter "
                     "and the recorders that must have the command)")
        ->check(CLI::Range(1, 1000));
  }
  int run(bus::Participant::Options& options, bus::ShutdownSignal& shutdown) override {
    options.dds.name = "navbus-command";
    return runCommandCommand(options, command, shutdown);
  }

 private:
  CommandOptions command;
};

class LatencyCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "latency",
        "latency over the bus: `ping` against a `pong` process (raw Fast DDS, navbus's message "
        "type), `imu` as the IMU of a running navbus-filter with the low-latency output "
        "(config/filter_latency.yaml): increment written -> output received, `observe` the same "
        "passively on a running bus (IMU source time stamp -> outputs received), or `flood` "
        "against "
        "a `sink` process: saturation throughput with zero loss checked (same domain, --profile, "
        "--qos); `table` runs ping/pong and navbus-filter + imu itself, idle and beside CPU-bound "
        "processes, with and without the real-time option, and prints the tail of each");
    cli_->add_option("role", latency.role, "ping, pong, imu, observe, flood, sink or table")
        ->required()
        ->check(CLI::IsMember({"ping", "pong", "imu", "observe", "flood", "sink", "table"}));
    cli_->add_option("--samples", latency.samples, "pings (flood: samples) timed after the warm-up")
        ->check(CLI::Range(1, 10'000'000));
    cli_->add_option("--warmup", latency.warmup, "pings sent first, not timed")
        ->check(CLI::Range(0, 1'000'000));
    cli_->add_option("--rate", latency.rate_hz, "ping rate [Hz]")->check(CLI::Range(0.1, 100000.0));
    cli_->add_option("--match-timeout", latency.match_timeout_s,
                     "seconds to wait for the other side")
        ->check(CLI::Range(0.1, 600.0));
    cli_->add_option("--duration", latency.pong_duration_s,
                     "pong, sink, observe: stop after this many seconds (0: until SIGINT; "
                     "a sink also stops when the flood ends its stream, observe after "
                     "--warmup + --samples outputs)");
    cli_->add_option("--writer-profile", latency.writer_profile,
                     "data writer profile of ping, pong, flood (default "
                     "navbus_sensor_writer; e.g. navbus_latency_best_effort_writer, or "
                     "one of your --qos file)");
    cli_->add_option("--reader-profile", latency.reader_profile,
                     "data reader profile of ping, pong, sink (default "
                     "navbus_sensor_reader; e.g. navbus_latency_best_effort_reader)");
    cli_->add_option("--csv", latency.csv,
                     "ping: every round trip [ns]; imu: every increment's latencies [ns] "
                     "(-1: not received); observe: every output's latency [ns]");
    addTableOptions();
  }
  int run(bus::Participant::Options& options, bus::ShutdownSignal& shutdown) override {
    options.dds.name = "navbus-latency-" + latency.role;
    if (latency.role == "table") return runTable(options);
    return runLatencyCommand(options, latency, shutdown);
  }

 private:
  void addTableOptions() {
    cli_->add_option("--rounds", table.rounds, "table: the whole table this many times (pooled)")
        ->check(CLI::Range(1, 100));
    cli_->add_option("--hogs", table.cpu_hogs, "table: CPU-bound processes beside the loaded rows")
        ->check(CLI::Range(0, 64));
    cli_->add_option("--filter-config", table.filter_config,
                     "table: navbus-filter's configuration (IMU sensor 1 at --rate, the "
                     "low-latency output on)")
        ->capture_default_str();
    cli_->add_option("--policy", table.policy, "table: the real-time rows' realtime.policy")
        ->check(CLI::IsMember({"fifo", "rr"}))
        ->capture_default_str();
    cli_->add_option("--priority", table.priority, "table: the real-time rows' realtime.priority")
        ->check(CLI::Range(1, 98))
        ->capture_default_str();
    cli_->add_option("--cpus", table.cpus,
                     "table: the real-time rows' realtime.cpus, for navbus-filter and its IMU "
                     "source alike (default: the last core)");
    cli_->add_flag("--spread", table.spread,
                   "table: no realtime.cpus in the real-time rows (their affinity as inherited)")
        ->excludes("--cpus");
    cli_->add_flag("--keep", table.keep, "table: keep its work directory (CSV files, logs)");
  }
  int runTable(const bus::Participant::Options& options) {
    // --samples, --warmup and --rate given: they apply to every row (else the table's defaults).
    if (cli_->count("--samples") > 0) table.samples = latency.samples;
    if (cli_->count("--warmup") > 0) table.warmup = latency.warmup;
    if (cli_->count("--rate") > 0) table.rate_hz = latency.rate_hz;
    try {
      return runLatencyTable(options, table);
    } catch (const std::exception& e) {  // a child that failed, a file it did not write
      spdlog::error("latency table: {}", e.what());
      return bus::kExitRuntimeError;
    }
  }

  LatencyOptions latency;
  LatencyTableOptions table;
};

}  // namespace

void addBusSubcommands(Subcommands& out) {
  out.push_back(std::make_unique<ReplayCommand>());
  out.push_back(std::make_unique<HealthCommand>());
  out.push_back(std::make_unique<CommandCommand>());
  out.push_back(std::make_unique<LatencyCommand>());
}

}  // namespace navbus::tool::cli
