// navbus: the user's tool for the bus: `topics`, `echo`, `record`, `latency`; offline runs.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>

#include <fastdds/dds/domain/DomainParticipantListener.hpp>

#include "navbus/bus/app.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/evaluation/evaluation.hpp"
#include "navbus/evaluation/real_data.hpp"
#include "navbus/tool/command.hpp"
#include "navbus/tool/health_check.hpp"
#include "navbus/tool/latency.hpp"
#include "navbus/tool/replay.hpp"
#include "navbus/tool/topic_registry.hpp"

namespace nb = navbus;
namespace fdds = eprosima::fastdds::dds;

namespace {

/// Collects discovered writers and readers by GUID.
class DiscoveryListener : public fdds::DomainParticipantListener {
 public:
  struct Endpoints {
    std::string type;
    std::set<std::string> writers, readers;
  };
  void on_publisher_discovery(fdds::DomainParticipant*,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
    update(info.info.topicName().to_string(), info.info.typeName().to_string(),
           guid(info.info.guid()), true,
           info.status == eprosima::fastrtps::rtps::WriterDiscoveryInfo::REMOVED_WRITER);
  }
  void on_subscriber_discovery(fdds::DomainParticipant*,
                               eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override {
    update(info.info.topicName().to_string(), info.info.typeName().to_string(),
           guid(info.info.guid()), false,
           info.status == eprosima::fastrtps::rtps::ReaderDiscoveryInfo::REMOVED_READER);
  }
  std::map<std::string, Endpoints> snapshot() {
    std::lock_guard<std::mutex> lock(mutex_);
    return topics_;
  }

 private:
  static std::string guid(const eprosima::fastrtps::rtps::GUID_t& g) {
    std::ostringstream out;
    out << g;
    return out.str();
  }
  void update(const std::string& topic, const std::string& type, const std::string& id, bool writer,
              bool removed) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto& e = topics_[topic];
    e.type = type;
    auto& set = writer ? e.writers : e.readers;
    if (removed)
      set.erase(id);
    else
      set.insert(id);
  }
  std::mutex mutex_;
  std::map<std::string, Endpoints> topics_;
};

/// Prints samples as text blocks or CSV lines.
class EchoSink : public nb::tool::SampleSink {
 public:
  EchoSink(bool csv, const std::string& header, std::uint64_t limit) : csv_(csv), limit_(limit) {
    if (csv_) std::cout << header << "\n";
  }
  void onSample(const std::string& topic, const nb::tool::SampleTimes&,
                const std::function<std::string()>& text,
                const std::function<std::vector<std::string>()>& rows) override {
    if (limit_ > 0 && count_ >= limit_) return;  // one dispatch round may hold more samples
    ++count_;
    if (csv_) {
      for (const auto& r : rows()) std::cout << r << "\n";
    } else {
      std::cout << "--- " << topic << " #" << count_ << "\n" << text();
    }
    std::cout.flush();
  }
  std::uint64_t count() const { return count_; }

 private:
  bool csv_;
  std::uint64_t limit_;
  std::uint64_t count_{0};
};

/// Writes one CSV file per topic: the message's columns, then when it was written (DDS source
/// time stamp) and received [ns, system clocks], so that `navbus replay` can pace it.
class RecordSink : public nb::tool::SampleSink {
 public:
  void open(const nb::tool::TopicEntry& e, const std::filesystem::path& dir) {
    const std::filesystem::path path = dir / nb::tool::recordFileName(e.name);
    auto& f = files_[e.name];
    f.stream = std::make_unique<std::ofstream>(path);
    if (!*f.stream) throw std::runtime_error("cannot write " + path.string());
    *f.stream << e.csv_header << ",source_timestamp_ns,reception_timestamp_ns\n";
  }
  void onSample(const std::string& topic, const nb::tool::SampleTimes& times,
                const std::function<std::string()>&,
                const std::function<std::vector<std::string>()>& rows) override {
    auto& f = files_.at(topic);
    ++f.samples;
    last_sample_ = std::chrono::steady_clock::now();
    for (const auto& r : rows()) {
      *f.stream << r << ',' << times.source_ns << ',' << times.reception_ns << '\n';
    }
  }
  void flush() {
    for (auto& [name, f] : files_) f.stream->flush();
  }
  std::uint64_t samples(const std::string& topic) const { return files_.at(topic).samples; }
  /// Seconds since the last sample of any topic; negative before the first.
  double idleSeconds() const {
    if (!last_sample_) return -1.0;
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - *last_sample_).count();
  }

 private:
  struct File {
    std::unique_ptr<std::ofstream> stream;
    std::uint64_t samples{0};
  };
  std::map<std::string, File> files_;
  std::optional<std::chrono::steady_clock::time_point> last_sample_;
};

const nb::tool::TopicEntry& requireTopic(const std::string& name) {
  const auto* e = nb::tool::findTopic(name);
  if (e == nullptr) {
    std::string known;
    for (const auto& t : nb::tool::topicRegistry()) known += " " + t.name;
    throw nb::bus::ConfigError("unknown topic '" + name + "'; navbus topics are:" + known);
  }
  return *e;
}

/// Runs the participant until `done()` or `duration_s` (0: until SIGINT/SIGTERM).
void runFor(nb::bus::Participant& p, double duration_s, const std::function<bool()>& done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s);
  while (!p.stopping() && !done() &&
         (duration_s <= 0.0 || std::chrono::steady_clock::now() < end)) {
    p.spinOnce(std::chrono::milliseconds(50));
  }
  p.finish();
}

}  // namespace

/// `--start` of offline and montecarlo: align from the inputs (true) or as the filter file says.
const std::map<std::string, bool> kStartChoices{{"align", true}, {"config", false}};

int main(int argc, char** argv) {
  nb::bus::ShutdownSignal shutdown;
  CLI::App app{"navbus: inspect and record the navbus DDS bus; offline evaluation", "navbus"};
  nb::bus::CommonOptions common;
  nb::bus::addCommonOptions(app, common, false);
  app.require_subcommand(1);
  bool publish_health = false;
  app.add_flag("--health", publish_health,
               "publish this tool's own health reports on navbus/health (off: the tool does not "
               "show up in the bus it inspects)");
  app.footer(
      "Exit codes: 0 ok, 1 fewer samples than --count, 2 usage or configuration error, 3 DDS "
      "error.");

  double wait_s = 2.0;
  auto* topics_cmd = app.add_subcommand(
      "topics", "list the topics seen on the bus with their writers and readers");
  topics_cmd->add_option("--wait", wait_s, "seconds of discovery before printing")
      ->check(CLI::Range(0.1, 600.0));

  std::string echo_topic;
  bool echo_csv = false;
  std::uint64_t count = 0;
  double duration_s = 0.0;
  auto* echo_cmd = app.add_subcommand("echo", "print the samples of one topic");
  echo_cmd->add_option("topic", echo_topic, "topic name, e.g. navbus/nav/solution")->required();
  echo_cmd->add_flag("--csv", echo_csv, "CSV instead of text");
  echo_cmd->add_option("-n,--count", count, "stop after this many samples (exit 1 if not reached)");
  echo_cmd->add_option("--duration", duration_s, "stop after this many seconds (0: until SIGINT)");

  std::vector<std::string> record_topics;
  std::string out_dir;
  auto* record_cmd = app.add_subcommand("record", "record topics into CSV files, one per topic");
  bool record_all = false;
  record_cmd->add_option("topics", record_topics, "topic names");
  record_cmd->add_flag("--all", record_all, "every navbus topic");
  record_cmd->add_option("-o,--out", out_dir, "output directory (created)")->required();
  record_cmd->add_option("-n,--count", count,
                         "stop when every topic has this many samples (exit 1 if not reached)");
  double idle_s = 0.0;
  record_cmd
      ->add_option("--idle", idle_s,
                   "stop once no sample of any topic came for this many seconds after the "
                   "first (0: never)")
      ->check(CLI::Range(0.0, 3600.0));
  record_cmd->add_option("--duration", duration_s,
                         "stop after this many seconds (0: until SIGINT)");

  nb::tool::ReplayOptions replay;
  auto* replay_cmd = app.add_subcommand(
      "replay",
      "publish a `navbus record` recording's sensor topics back onto the bus, content unchanged, "
      "paced by their data times (or the recorded source time stamps) scaled by --speed; the "
      "streams are disposed at the end");
  replay_cmd->add_option("dir", replay.dir, "the recording's directory")
      ->required()
      ->check(CLI::ExistingDirectory);
  replay_cmd
      ->add_option("--speed", replay.speed, "1: as recorded, 10: ten times faster, 0: no pacing")
      ->check(CLI::Range(0.0, 1e6));
  replay_cmd
      ->add_option("--pace", replay.pace,
                   "data: by the samples' data times; source: by the recorded DDS source time "
                   "stamps (the bus timing of the recording)")
      ->check(CLI::IsMember({"data", "source"}));
  replay_cmd->add_option("--topics", replay.topics,
                         "only these topics (default: every sensor topic recorded)");
  replay_cmd->add_option("--min-readers", replay.min_readers,
                         "TOPIC=N: wait for N readers of TOPIC before the first sample (default "
                         "1 each), e.g. navbus/imu/increment_block=2 for a filter and a fault "
                         "manager");
  replay_cmd
      ->add_option("--match-timeout", replay.match_timeout_s,
                   "seconds to wait for a reader of every replayed topic")
      ->check(CLI::Range(0.1, 600.0));

  nb::tool::HealthCheckOptions health;
  auto* health_cmd = app.add_subcommand(
      "health",
      "exit 0 if PARTICIPANT's own health reports say RUNNING or DEGRADED within --timeout, 1 "
      "otherwise (no report, STARTING, STOPPING); for container healthchecks and scripts");
  health_cmd->add_option("participant", health.participant, "e.g. navbus-filter")->required();
  health_cmd->add_option("--timeout", health.timeout_s, "seconds to wait for a working report")
      ->check(CLI::Range(0.1, 600.0));

  nb::tool::CommandOptions command;
  auto* command_cmd = app.add_subcommand(
      "command",
      "send one FilterCommand to navbus-filter and wait for its acknowledgment (enums by name, "
      "with or without their IDL prefix; units as in idl/Fault.idl)");
  command_cmd
      ->add_option("kind", command.kind,
                   "EXCLUDE_SATELLITE, READMIT_SATELLITE, COMPENSATE_BIAS, SELECT_FUSION, "
                   "SELECT_MODE, RESET, EXCLUDE_STREAM, READMIT_STREAM, FAIL_SENSOR_AXIS, "
                   "RESTORE_SENSOR_AXIS, RELEARN_BIAS")
      ->required();
  command_cmd->add_option("--vehicle", command.vehicle_id, "vehicle_id of the filter addressed");
  command_cmd->add_option("--sv", command.sv_id, "GPS PRN (satellite commands)");
  command_cmd->add_option("--scope", command.scope, "ALL, PSEUDORANGE or PSEUDORANGE_RATE");
  command_cmd->add_option("--sensor", command.sensor,
                          "ACCELEROMETER or GYRO (bias and axis commands); IMU_STREAM, "
                          "GNSS_OBS_STREAM, ... (stream commands)");
  command_cmd->add_option("--sensor-id", command.sensor_id, "the stream's sensor id");
  command_cmd->add_option("--axis", command.axis, "body axis 0, 1 or 2");
  command_cmd->add_option("--bias", command.bias, "bias to compensate [m/s^2 or rad/s, body]");
  command_cmd->add_option("--bias-sigma", command.bias_sigma, "its 1-sigma [m/s^2 or rad/s]");
  command_cmd->add_option("--fusion", command.fusion, "CENTRALIZED, FEDERATED or ADAPTIVE");
  command_cmd->add_option("--mode", command.mode, "a FilterMode, e.g. TIGHTLY_COUPLED");
  command_cmd->add_option("--time-gps-ns", command.time_gps_ns,
                          "data time the command refers to [ns, GPS time] (0: at once)");
  command_cmd->add_option("--onset-gps-ns", command.onset_time_gps_ns,
                          "estimated onset of the fault it answers [ns, GPS time]");
  command_cmd->add_option("--decision-id", command.decision_id,
                          "the decision it follows (0: none)");
  command_cmd->add_option("--issuer", command.issuer, "issuer (the filter obeys configured ones)");
  command_cmd->add_option("--command-id", command.command_id,
                          "unique per issuer, increasing (default: this run's start time [ns])");
  command_cmd
      ->add_option("--match-timeout", command.match_timeout_s,
                   "seconds to wait for the filter's reader and its acknowledgment")
      ->check(CLI::Range(0.1, 600.0));

  nb::tool::LatencyOptions latency;
  auto* latency_cmd = app.add_subcommand(
      "latency",
      "latency over the bus: `ping` against a `pong` process (raw Fast DDS, navbus's message "
      "type), `imu` as the IMU of a running navbus-filter with the low-latency output "
      "(config/filter_latency.yaml): increment written -> output received, `observe` the same "
      "passively on a running bus (IMU source time stamp -> outputs received), or `flood` against "
      "a `sink` process: saturation throughput with zero loss checked (same domain, --profile, "
      "--qos)");
  latency_cmd->add_option("role", latency.role, "ping, pong, imu, observe, flood or sink")
      ->required()
      ->check(CLI::IsMember({"ping", "pong", "imu", "observe", "flood", "sink"}));
  latency_cmd
      ->add_option("--samples", latency.samples, "pings (flood: samples) timed after the warm-up")
      ->check(CLI::Range(1, 10'000'000));
  latency_cmd->add_option("--warmup", latency.warmup, "pings sent first, not timed")
      ->check(CLI::Range(0, 1'000'000));
  latency_cmd->add_option("--rate", latency.rate_hz, "ping rate [Hz]")
      ->check(CLI::Range(0.1, 100000.0));
  latency_cmd
      ->add_option("--match-timeout", latency.match_timeout_s, "seconds to wait for the other side")
      ->check(CLI::Range(0.1, 600.0));
  latency_cmd->add_option("--duration", latency.pong_duration_s,
                          "pong, sink, observe: stop after this many seconds (0: until SIGINT; "
                          "a sink also stops when the flood ends its stream, observe after "
                          "--warmup + --samples outputs)");
  latency_cmd->add_option("--writer-profile", latency.writer_profile,
                          "data writer profile of ping, pong, flood (default "
                          "navbus_sensor_writer; e.g. navbus_latency_best_effort_writer, or "
                          "one of your --qos file)");
  latency_cmd->add_option("--reader-profile", latency.reader_profile,
                          "data reader profile of ping, pong, sink (default "
                          "navbus_sensor_reader; e.g. navbus_latency_best_effort_reader)");
  latency_cmd->add_option("--csv", latency.csv,
                          "ping: every round trip [ns]; imu: every increment's latencies [ns] "
                          "(-1: not received); observe: every output's latency [ns]");

  nb::evaluation::OfflineOptions offline;
  auto* offline_cmd = app.add_subcommand(
      "offline", "run a scenario through the filter without DDS; write solution, truth, error CSV");
  offline_cmd->add_option("--scenario", offline.scenario, "scenario YAML (sim/scenarios)")
      ->required()
      ->check(CLI::ExistingFile);
  offline_cmd->add_option("--filter", offline.filter, "navbus-filter YAML (config/)")
      ->required()
      ->check(CLI::ExistingFile);
  offline_cmd->add_option("--seed", offline.seed, "random seed (0: the scenario's)");
  offline_cmd
      ->add_option("--duration", offline.duration_s,
                   "seconds of data (0: the scenario's timing.duration_s)")
      ->check(CLI::Range(0.0, 1e6));
  offline_cmd->add_option("-o,--out", offline.out_dir, "output directory (created)")->required();
  offline_cmd
      ->add_option("--start", offline.align,
                   "align: the filter aligns from its inputs, as on a bus where nobody knows the "
                   "truth (default); config: it starts as the filter YAML says (its initial_state "
                   "if it has one), as navbus-filter with that file would")
      ->transform(CLI::CheckedTransformer(kStartChoices))
      ->default_str("align");
  offline_cmd
      ->add_option("--fault-manager", offline.fault_manager,
                   "navbus-fault-manager YAML: run the fault pipeline (GLR) in the same process, "
                   "its commands to the filter; writes decisions.csv and commands.csv")
      ->check(CLI::ExistingFile);

  nb::evaluation::MonteCarloOptions mc;
  bool mc_no_perturb = false;
  auto* mc_cmd = app.add_subcommand(
      "montecarlo", "Monte Carlo over seeds: RMS and max errors, average NEES with its 95% band");
  mc_cmd->add_option("--scenario", mc.scenario, "scenario YAML")
      ->required()
      ->check(CLI::ExistingFile);
  mc_cmd->add_option("--filter", mc.filters, "navbus-filter YAML, repeatable (one row each)")
      ->required()
      ->check(CLI::ExistingFile);
  mc_cmd
      ->add_option("--fusion", mc.fusions,
                   "override `fusion` of every filter: centralized federated adaptive")
      ->delimiter(',');
  mc_cmd
      ->add_option("--policy", mc.policies,
                   "override multi_dimensional.policy: mdf continue reset_all")
      ->delimiter(',');
  mc_cmd->add_option("--runs", mc.runs, "runs per configuration")->check(CLI::Range(1, 100000));
  mc_cmd
      ->add_option("--fault-manager", mc.fault_manager,
                   "navbus-fault-manager YAML: run the fault pipeline and report detection time, "
                   "isolation, magnitude error and false alarms per configuration")
      ->check(CLI::ExistingFile);
  mc_cmd->add_option("--csv", mc.csv_dir,
                     "directory for nees.csv (average NEES per epoch, 95 % band) and, with "
                     "--fault-manager, faults.csv (one row per run)");
  mc_cmd->add_option("--threads", mc.threads, "parallel runs (0: one per core)")
      ->check(CLI::Range(0, 256));
  mc_cmd->add_option("--first-seed", mc.first_seed, "seed of the first run (then +1 per run)")
      ->check(CLI::Range(1ull, 1ull << 60));
  mc_cmd->add_option("--duration", mc.duration_s, "seconds of data (0: the scenario's)")
      ->check(CLI::Range(0.0, 1e6));
  mc_cmd->add_option("--from", mc.from_s, "statistics from this many seconds after the start")
      ->check(CLI::Range(0.0, 1e6));
  mc_cmd->add_flag("--no-perturb", mc_no_perturb,
                   "start every run at the true initial state instead of a draw from the "
                   "filter's initial sigmas");
  mc_cmd
      ->add_option("--start", mc.align,
                   "align: every filter aligns from its inputs (default; prints the alignment's "
                   "time, attitude source and start error against its sigmas); config: a filter "
                   "with an initial_state starts from a draw around the truth with its initial "
                   "sigmas (--no-perturb: the truth), one without aligns")
      ->transform(CLI::CheckedTransformer(kStartChoices))
      ->default_str("align");
  mc_cmd
      ->add_option("--recovery-after", mc.recovery_after_s,
                   "instants [s after start] after which to measure the convergence time")
      ->delimiter(',');
  mc_cmd
      ->add_option("--recovery-threshold", mc.recovery_threshold_m,
                   "horizontal position error [m] that counts as converged")
      ->check(CLI::Range(1e-6, 1e6));
  mc_cmd
      ->add_option("--recovery-window", mc.recovery_window_s,
                   "the error must stay below the threshold this long [s]")
      ->check(CLI::Range(0.0, 1e6));

  nb::evaluation::RealDataOptions real;
  auto* rinex_cmd = app.add_subcommand(
      "rinex",
      "real GPS data: RINEX 2 observation + navigation files -> single point fixes and the static "
      "receiver filter, optionally monitored by the fault manager's GLR");
  rinex_cmd->add_option("--obs", real.obs, "RINEX 2 observation file (.yyo)")
      ->required()
      ->check(CLI::ExistingFile);
  rinex_cmd->add_option("--nav", real.nav, "RINEX 2 GPS navigation file (.yyn)")
      ->required()
      ->check(CLI::ExistingFile);
  rinex_cmd->add_option("-o,--out", real.out_dir, "output directory (created)")->required();
  rinex_cmd
      ->add_option("--fault-manager", real.fault_manager,
                   "navbus-fault-manager YAML (e.g. config/fault_manager_static.yaml): run the "
                   "GLR on the filter; writes decisions.csv and commands.csv")
      ->check(CLI::ExistingFile);
  rinex_cmd
      ->add_option("--reference", real.reference,
                   "reference position x,y,z ECEF [m] (default: the header's APPROX POSITION)")
      ->delimiter(',');
  rinex_cmd
      ->add_option("--inject-ramp", real.ramp,
                   "sv,rate_mps,onset_s: add rate * (t - onset) to one satellite's pseudoranges "
                   "from onset_s after the first epoch")
      ->delimiter(',');

  return nb::bus::runMain(app, argc, argv, common, [&](const YAML::Node& yaml) -> int {
    // Offline work: no DDS participant at all.
    if (*offline_cmd) return nb::evaluation::runOfflineCommand(offline);
    if (*rinex_cmd) return nb::evaluation::runRealDataCommand(real);
    if (*mc_cmd) {
      mc.perturb_initial = !mc_no_perturb;
      return nb::evaluation::runMonteCarloCommand(mc);
    }
    auto options = nb::bus::participantOptions(common, yaml, "navbus");
    options.publish_health = publish_health;  // an inspection tool is not part of what it inspects
    // Under a discovery server, the inspection tools see every endpoint, not only their matches.
    options.dds.discovery_super_client = *topics_cmd || *echo_cmd || *record_cmd;
    if (*latency_cmd) {
      options.dds.name = "navbus-latency-" + latency.role;
      return nb::tool::runLatencyCommand(options, latency, shutdown);
    }
    if (*replay_cmd) {
      options.dds.name = "navbus-replay";
      return nb::tool::runReplayCommand(options, replay, shutdown);
    }
    if (*health_cmd) {
      options.dds.name = "navbus-health";
      return nb::tool::runHealthCommand(options, health, shutdown);
    }
    if (*command_cmd) {
      options.dds.name = "navbus-command";
      return nb::tool::runCommandCommand(options, command, shutdown);
    }
    if (*topics_cmd) {
      DiscoveryListener listener;
      options.dds.listener = &listener;
      nb::bus::Participant p(options, shutdown);
      runFor(p, wait_s, [] { return false; });
      std::printf("%-30s %-36s %8s %8s\n", "TOPIC", "TYPE", "WRITERS", "READERS");
      for (const auto& [topic, e] : listener.snapshot()) {
        std::printf("%-30s %-36s %8zu %8zu\n", topic.c_str(), e.type.c_str(), e.writers.size(),
                    e.readers.size());
      }
      return nb::bus::kExitOk;
    }
    if (*echo_cmd) {
      const auto& entry = requireTopic(echo_topic);
      nb::bus::Participant p(options, shutdown);
      EchoSink sink(echo_csv, entry.csv_header, count);
      entry.subscribe(p, sink);
      runFor(p, duration_s, [&] { return count > 0 && sink.count() >= count; });
      return (count > 0 && sink.count() < count) ? nb::bus::kExitRuntimeError : nb::bus::kExitOk;
    }
    // record
    std::filesystem::create_directories(out_dir);
    nb::bus::Participant p(options, shutdown);
    RecordSink sink;
    std::vector<const nb::tool::TopicEntry*> entries;
    if (record_all) {
      for (const auto& t : nb::tool::topicRegistry()) record_topics.push_back(t.name);
    }
    if (record_topics.empty()) {
      throw nb::bus::ConfigError("record: name the topics, or --all");
    }
    for (const auto& t : record_topics) {
      entries.push_back(&requireTopic(t));
      sink.open(*entries.back(), out_dir);
      entries.back()->subscribe(p, sink);
    }
    auto all_counted = [&] {
      if (idle_s > 0.0 && sink.idleSeconds() >= idle_s) return true;
      if (count == 0) return false;
      for (const auto* e : entries)
        if (sink.samples(e->name) < count) return false;
      return true;
    };
    runFor(p, duration_s, all_counted);
    sink.flush();
    bool reached = true;
    for (const auto* e : entries) {
      spdlog::info("recorded {} samples of {}", sink.samples(e->name), e->name);
      reached = reached && sink.samples(e->name) >= count;
    }
    return reached ? nb::bus::kExitOk : nb::bus::kExitRuntimeError;
  });
}
