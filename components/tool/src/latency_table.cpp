// `navbus latency table`: the raw Fast DDS round trip and navbus's IMU -> low-latency output,
// with and without the real-time option, idle and beside CPU-bound processes, one after the
// other in the same few minutes, as one table (the tail included: p99.9, p99.99, max).
//
// Every measurement is a pair of child processes this command starts: `navbus latency pong` +
// `navbus latency ping` (raw), or navbus-filter + `navbus latency imu` (navbus), each pair on a
// domain of its own, each writing its samples to a CSV file that is read back here. The
// CPU-bound processes are children forked by this process (which creates no DDS participant;
// its only other thread waits for SIGINT/SIGTERM), each spinning, touching nothing shared,
// until it is killed at the end of the loaded rows.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "navbus/bus/app.hpp"
#include "navbus/bus/proc_status.hpp"
#include "navbus/bus/realtime.hpp"
#include "navbus/tool/latency.hpp"

extern char** environ;

namespace navbus::tool {

namespace {

namespace fs = std::filesystem;

/// A child process started with posix_spawn, its output into a log file.
class Child {
 public:
  Child(const std::vector<std::string>& argv, const fs::path& log) {
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    const int error = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (error != 0) {
      throw std::runtime_error("could not start " + argv[0] + ": " + std::strerror(error));
    }
  }
  ~Child() { stop(SIGKILL, 0.0); }
  pid_t pid() const { return pid_; }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  /// Waits up to `timeout_s` for the exit; -1 if it is still running (then killed).
  int wait(double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (pid_ > 0) {
      int status = 0;
      const pid_t r = waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      if (std::chrono::steady_clock::now() > end) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    stop(SIGKILL, 0.0);
    return -1;
  }
  /// Sends `signal`, then waits up to `grace_s` before SIGKILL.
  void stop(int signal, double grace_s) {
    if (pid_ <= 0) return;
    kill(pid_, signal);
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(grace_s);
    int status = 0;
    while (waitpid(pid_, &status, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > end) {
        kill(pid_, SIGKILL);
        waitpid(pid_, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    pid_ = -1;
  }

 private:
  pid_t pid_{-1};
};

/// CPU-bound children: each spins until killed (forked: this process has no other thread).
class CpuHogs {
 public:
  explicit CpuHogs(int count) {
    for (int i = 0; i < count; ++i) {
      const pid_t pid = fork();
      if (pid == 0) {
        volatile std::uint64_t spin = 0;
        for (;;) spin = spin + 1;
      }
      if (pid > 0) pids_.push_back(pid);
    }
  }
  ~CpuHogs() {
    for (const pid_t pid : pids_) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
  CpuHogs(const CpuHogs&) = delete;
  CpuHogs& operator=(const CpuHogs&) = delete;

 private:
  std::vector<pid_t> pids_;
};

/// The non-negative values of one column of a CSV file a child wrote (a header line first);
/// throws naming the file and line when a cell is not an integer.
std::vector<std::int64_t> readColumn(const fs::path& csv, int column) {
  std::ifstream in(csv);
  if (!in) throw std::runtime_error("cannot read " + csv.string());
  std::vector<std::int64_t> out;
  std::string line;
  std::getline(in, line);  // header
  for (int number = 2; std::getline(in, line); ++number) {
    std::stringstream row(line);
    std::string cell;
    for (int c = 0; c <= column && std::getline(row, cell, ','); ++c) {
    }
    std::size_t used = 0;
    std::int64_t v = -1;
    try {
      v = std::stoll(cell, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != cell.size()) {
      throw std::runtime_error(csv.string() + " line " + std::to_string(number) + ": '" + cell +
                               "' is not an integer");
    }
    if (v >= 0) out.push_back(v);
  }
  return out;
}

std::string tail(const fs::path& log) {
  std::ifstream in(log);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  std::string out;
  for (std::size_t i = lines.size() > 6 ? lines.size() - 6 : 0; i < lines.size(); ++i)
    out += "    " + lines[i] + "\n";
  return out;
}

struct Row {
  std::string state, path;
  std::vector<std::int64_t> samples;  ///< [ns]
  LatencyStats stats;
  std::size_t expected{0};
  long filter_peak_kib{-1};  ///< navbus-filter's VmHWM at the end of the row (-1: raw row)
};

Row makeRow(const std::string& state, const std::string& path, std::vector<std::int64_t> samples,
            std::size_t expected) {
  Row r{state, path, std::move(samples), {}, expected, -1};
  r.stats = latencyStats(r.samples);
  return r;
}

/// The real-time rows' cores: as given, each one this machine has, or the last core (none with
/// --spread).
std::vector<int> realtimeCpus(const LatencyTableOptions& o) {
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  if (o.spread) return {};
  if (o.cpus.empty()) return {static_cast<int>(std::max(online, 1L)) - 1};
  for (const int cpu : o.cpus) {
    if (cpu < 0 || cpu >= online) {
      throw std::runtime_error("--cpus " + std::to_string(cpu) + ": this machine has cores 0.." +
                               std::to_string(online - 1));
    }
  }
  return o.cpus;
}

class TableRun {
 public:
  TableRun(const bus::Participant::Options& participant, const LatencyTableOptions& o)
      : participant_(participant), o_(o) {
    self_ = fs::read_symlink("/proc/self/exe");
    filter_ = self_.parent_path() / "navbus-filter";
    if (!fs::exists(filter_)) {
      throw std::runtime_error("navbus-filter not found beside this program (" + filter_.string() +
                               ")");
    }
    if (!fs::exists(o.filter_config)) {
      throw std::runtime_error("--filter-config '" + o.filter_config + "': no such file");
    }
    char dir_template[] = "/tmp/navbus-latency-table.XXXXXX";
    if (mkdtemp(dir_template) == nullptr) throw std::runtime_error("mkdtemp failed");
    work_ = dir_template;
    writeRealtimeFiles();
  }
  ~TableRun() {
    if (!o_.keep) {
      std::error_code ec;
      fs::remove_all(work_, ec);
    }
  }

  Row raw(const std::string& state) {
    const std::string d = nextDomain();
    const fs::path csv = work_ / ("raw_" + state + ".csv");
    Child pong(
        toolArgs(d, false,
                 {"latency", "pong", "--duration", std::to_string(o_.samples / o_.rate_hz + 60.0)}),
        work_ / ("pong_" + state + ".log"));
    Child ping(toolArgs(d, false, sampleArgs("ping", csv)), work_ / ("ping_" + state + ".log"));
    expectExit(ping, "ping", state, work_ / ("ping_" + state + ".log"));
    pong.stop(SIGTERM, 5.0);
    return makeRow(state, "raw Fast DDS round trip", readColumn(csv, 0),
                   static_cast<std::size_t>(o_.samples));
  }

  Row navbus(const std::string& state, bool realtime) {
    const std::string d = nextDomain();
    const std::string tag = state + (realtime ? "_rt" : "");
    const fs::path csv = work_ / ("imu_" + tag + ".csv");
    const fs::path filter_log = work_ / ("filter_" + tag + ".log");
    std::vector<std::string> filter_args{
        filter_.string(),
        "-c",
        realtime ? (work_ / "filter_realtime.yaml").string() : o_.filter_config,
        "-d",
        d,
        "--log-level",
        "warn"};
    appendTransport(filter_args);
    Child filter(filter_args, filter_log);
    Child imu(toolArgs(d, realtime, sampleArgs("imu", csv)), work_ / ("imu_" + tag + ".log"));
    expectExit(imu, "imu", tag, work_ / ("imu_" + tag + ".log"));
    const long filter_peak_kib = bus::procStatusKilobytes(std::to_string(filter.pid()), "VmHWM");
    filter.stop(SIGTERM, 5.0);
    Row row = makeRow(state, realtime ? "navbus, real-time option" : "navbus", readColumn(csv, 1),
                      static_cast<std::size_t>(o_.samples));
    row.filter_peak_kib = filter_peak_kib;
    return row;
  }

 private:
  void writeRealtimeFiles() {
    const std::string block =
        "realtime: {policy: " + o_.policy + ", priority: " + std::to_string(o_.priority) +
        (o_.cpus.empty() ? "" : ", cpus: " + bus::cpuListText(o_.cpus)) + ", lock_memory: true}\n";
    std::ofstream(work_ / "tool_realtime.yaml") << block;
    std::ofstream(work_ / "filter_realtime.yaml")
        << "extends: " << fs::absolute(o_.filter_config).string() << "\n"
        << block;
  }
  std::string nextDomain() { return std::to_string(participant_.dds.domain_id + domain_offset_++); }
  std::vector<std::string> toolArgs(const std::string& domain, bool realtime,
                                    const std::vector<std::string>& rest) const {
    std::vector<std::string> a{self_.string(), "-d", domain, "--log-level", "warn"};
    if (realtime) {
      a.push_back("-c");
      a.push_back((work_ / "tool_realtime.yaml").string());
    }
    appendTransport(a);
    a.insert(a.end(), rest.begin(), rest.end());
    return a;
  }
  /// The participant profile and QoS file this command was given, for every child.
  void appendTransport(std::vector<std::string>& a) const {
    if (!participant_.dds.participant_profile.empty()) {
      a.push_back("--profile");
      a.push_back(participant_.dds.participant_profile);
    }
    if (!participant_.dds.qos_file.empty()) {
      a.push_back("--qos");
      a.push_back(participant_.dds.qos_file);
    }
  }
  std::vector<std::string> sampleArgs(const std::string& role, const fs::path& csv) const {
    return {"latency",   role,
            "--samples", std::to_string(o_.samples),
            "--warmup",  std::to_string(o_.warmup),
            "--rate",    std::to_string(o_.rate_hz),
            "--csv",     csv.string()};
  }
  void expectExit(Child& c, const std::string& what, const std::string& tag, const fs::path& log) {
    const double budget_s = (o_.samples + o_.warmup) / o_.rate_hz + 60.0;
    const int rc = c.wait(budget_s);
    if (rc != 0) {
      throw std::runtime_error("latency " + what + " (" + tag + ") " +
                               (rc < 0 ? "did not end in time" : "exited " + std::to_string(rc)) +
                               "; its log " + log.string() + " ends:\n" + tail(log));
    }
  }

  bus::Participant::Options participant_;
  LatencyTableOptions o_;
  fs::path self_, filter_, work_;
  int domain_offset_{0};
};

std::vector<double> quantiles(const LatencyStats& s) {
  return {s.median_ns, s.p99_ns, s.p999_ns, s.p9999_ns, s.max_ns};
}

void printRow(const Row& r) {
  std::printf("%-7s %-26s", r.state.c_str(), r.path.c_str());
  for (const double ns : quantiles(r.stats)) std::printf(" %9.1f", ns / 1000.0);
  std::printf("  %zu of %zu", r.stats.count, r.expected);
  if (r.filter_peak_kib > 0) {
    std::printf("  (navbus-filter VmHWM %.1f MiB)",
                static_cast<double>(r.filter_peak_kib) / 1024.0);
  }
  std::printf("\n");
}

void printRatios(const Row& r, const Row& raw) {
  std::printf("%-7s %-26s", r.state.c_str(), r.path.c_str());
  const auto a = quantiles(r.stats), b = quantiles(raw.stats);
  for (std::size_t i = 0; i < a.size(); ++i) std::printf(" %9.2f", b[i] > 0 ? a[i] / b[i] : 0.0);
  std::printf("\n");
}

/// One target: `value / raw <= limit`, printed with its verdict; true when met.
bool target(const char* what, double value_ns, double raw_ns, double limit) {
  const double ratio = raw_ns > 0 ? value_ns / raw_ns : 0.0;
  const bool met = raw_ns > 0 && ratio <= limit;
  std::printf("  %-52s %.2fx (target <= %.1fx): %s\n", what, ratio, limit, met ? "met" : "NOT met");
  return met;
}

/// The samples of all rounds of one row pooled.
struct Pool {
  std::vector<Row> rows;  ///< one per round
  Row pooled() const {
    Row out = rows.front();
    out.expected = 0;
    std::vector<std::int64_t> all;
    for (const Row& r : rows) {
      all.insert(all.end(), r.samples.begin(), r.samples.end());
      out.expected += r.expected;
      out.filter_peak_kib = std::max(out.filter_peak_kib, r.filter_peak_kib);
    }
    out.stats = latencyStats(all);
    return out;
  }
};

}  // namespace

int runLatencyTable(const bus::Participant::Options& participant,
                    const LatencyTableOptions& options) {
  LatencyTableOptions o = options;
  o.cpus = realtimeCpus(options);
  TableRun run(participant, o);
  // The second state is "idle again" when no CPU-bound process was asked for.
  const char* states[] = {"idle", o.cpu_hogs > 0 ? "loaded" : "idle-2"};
  std::vector<Pool> pools(6);
  const auto started = std::chrono::steady_clock::now();
  for (int round = 0; round < o.rounds; ++round) {
    for (int s = 0; s < 2; ++s) {
      const bool loaded = s == 1;
      std::fprintf(
          stderr, "latency table: round %d of %d, %s%s\n", round + 1, o.rounds, states[s],
          loaded ? (" (" + std::to_string(o.cpu_hogs) + " CPU-bound processes)").c_str() : "");
      CpuHogs hogs(loaded ? o.cpu_hogs : 0);
      pools[3 * s + 0].rows.push_back(run.raw(states[s]));
      pools[3 * s + 1].rows.push_back(run.navbus(states[s], false));
      pools[3 * s + 2].rows.push_back(run.navbus(states[s], true));
    }
  }
  const double minutes =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() / 60.0;
  std::vector<Row> rows;
  for (const Pool& p : pools) rows.push_back(p.pooled());

  std::printf(
      "navbus latency table: %d round(s) of %d samples per row at %.0f Hz (after %d warm-up), "
      "%.1f min in all; loaded: %d CPU-bound processes beside it; real-time option: policy %s, "
      "priority %d, memory locked, cpus %s (navbus-filter and its IMU source)\n"
      "raw: navbus latency ping/pong round trip (two hops, default priority); navbus: IMU "
      "increment written -> low-latency output received (two hops through navbus-filter)\n\n",
      o.rounds, o.samples, o.rate_hz, o.warmup, minutes, o.cpu_hogs, o.policy.c_str(), o.priority,
      o.cpus.empty() ? "as inherited" : bus::cpuListText(o.cpus).c_str());
  std::printf("%-7s %-26s %9s %9s %9s %9s %9s  samples\n", "[us]", "", "p50", "p99", "p99.9",
              "p99.99", "max");
  for (const Row& r : rows) printRow(r);
  std::printf("\nratio to the raw round trip of the same state\n");
  for (int s = 0; s < 2; ++s) {
    printRatios(rows[3 * s + 1], rows[3 * s]);
    printRatios(rows[3 * s + 2], rows[3 * s]);
  }
  if (rows.front().stats.count < 10000) {
    std::printf("(p99.99 of fewer than 10,000 samples is their maximum, nearest rank)\n");
  }
  const Row &idle_raw = rows[0], &idle_rt = rows[2], &loaded_raw = rows[3], &loaded_rt = rows[5];
  std::printf("\ntargets\n");
  bool met = true;
  met &= target("loaded, real-time option: p99.9 / raw p99.9", loaded_rt.stats.p999_ns,
                loaded_raw.stats.p999_ns, 0.3);
  met &= target("loaded, real-time option: max / raw max", loaded_rt.stats.max_ns,
                loaded_raw.stats.max_ns, 1.0);
  met &= target("idle, real-time option: p50 / raw p50", idle_rt.stats.median_ns,
                idle_raw.stats.median_ns, 1.0);
  met &= target("idle, real-time option: p99 / raw p99", idle_rt.stats.p99_ns,
                idle_raw.stats.p99_ns, 1.0);
  std::printf("%s\n", met ? "all targets met" : "not every target met");
  bool complete = true;
  for (const Row& r : rows) complete &= r.stats.count == r.expected;
  if (!complete) std::printf("some samples were not received (the samples column)\n");
  return complete ? bus::kExitOk : bus::kExitRuntimeError;
}

}  // namespace navbus::tool
