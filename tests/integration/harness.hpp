// Helpers for multi-process tests: child processes, temporary files, a test subscriber.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "navbus/bus/participant.hpp"
#include "navbus/bus/shared_memory.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/sim/scenario_source.hpp"
#include "test_paths.hpp"

namespace navbus::test {

/// A navbus executable run as a child process, its output in a log file. It leads its own
/// process group, so that signals reach what it starts too (`fastdds discovery` is a launcher
/// that starts fast-discovery-server as its child: killing the launcher alone left the server
/// running after the test). Killed, with its group, if still running when destroyed, and
/// killed when the test process dies.
class ChildProcess {
 public:
  ChildProcess(const std::string& exe, const std::vector<std::string>& args,
               const std::string& log) {
    pid_ = fork();
    if (pid_ == 0) {
      setpgid(0, 0);
      // Dies with the test process, even when that one aborts (a sanitizer finding) and no
      // destructor runs: a stray participant would disturb the next test on its domain.
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      // The test process blocks SIGINT/SIGTERM (ShutdownSignal); the child must not inherit it.
      sigset_t none;
      sigemptyset(&none);
      sigprocmask(SIG_SETMASK, &none, nullptr);
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(fd, 1);
      dup2(fd, 2);
      std::vector<char*> argv;
      argv.push_back(const_cast<char*>(exe.c_str()));
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(exe.c_str(), argv.data());
      _exit(127);
    }
    setpgid(pid_, pid_);  // also here: whichever of parent and child runs first
  }
  ~ChildProcess() {
    const bool was_running = running();
    kill(-pid_, SIGKILL);  // the group: children the process left behind too
    if (was_running) waitpid(pid_, nullptr, 0);
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  void signal(int sig) { kill(-pid_, sig); }
  bool running() {
    if (exited_) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      exited_ = true;
      exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      return false;
    }
    return true;
  }
  /// Waits for the exit; returns the exit code (128 + signal if killed), nullopt on timeout.
  std::optional<int> wait(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (running()) {
      if (std::chrono::steady_clock::now() > end) return std::nullopt;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return exit_code_;
  }

 private:
  pid_t pid_{-1};
  bool exited_{false};
  int exit_code_{-1};
};

/// A per-test scratch directory under the build tree.
inline std::filesystem::path scratchDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("navbus-test-" + name + "-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string writeFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path.string();
}

inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Solution rows that differ between a bus run and the offline run; the first three are
/// reported as failures.
inline std::size_t countDiffering(const std::vector<std::string>& bus,
                                  const std::vector<std::string>& offline) {
  std::size_t differing = 0;
  for (std::size_t i = 0; i < bus.size() && i < offline.size(); ++i) {
    if (bus[i] != offline[i] && differing++ < 3) {
      ADD_FAILURE() << "solution " << i << " differs:\n bus:     " << bus[i]
                    << "\n offline: " << offline[i];
    }
  }
  return differing;
}

/// The lines of a CSV file after its header.
inline std::vector<std::string> csvDataRows(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> rows;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) rows.push_back(line);
  return rows;
}

/// The test's own participant on the bus.
inline bus::Participant::Options testParticipant(int domain, const std::string& name) {
  bus::Participant::Options o;
  o.dds.domain_id = domain;
  o.dds.participant_profile = bus::profile::kParticipantLoopback;
  o.dds.name = name;
  o.health_period = std::chrono::milliseconds(1000);
  return o;
}

/// Spins the participant until pred() holds or the timeout passes; returns pred().
inline bool spinUntil(bus::Participant& p, std::chrono::milliseconds timeout,
                      const std::function<bool()>& pred) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!pred() && std::chrono::steady_clock::now() < end)
    p.spinOnce(std::chrono::milliseconds(10));
  return pred();
}

/// Removes the shared memory of dead Fast DDS processes (bus/shared_memory.hpp); what live
/// processes use, those of tests running in parallel among them, is left alone.
inline void cleanSharedMemory() {
  bus::reclaimSharedMemory();
}

/// The test's writers for every sensor stream navbus-filter reads, with the simulator's profiles.
struct SensorInputWriters {
  explicit SensorInputWriters(bus::Participant& p)
      : imu(p.createWriter<ImuIncrementPubSubType>(bus::topic::kImuIncrement,
                                                   bus::profile::kSensorWriter)),
        obs(p.createWriter<GnssObservationEpochPubSubType>(bus::topic::kGnssObservations,
                                                           bus::profile::kMeasurementWriter)),
        fix(p.createWriter<GnssFixPubSubType>(bus::topic::kGnssFix,
                                              bus::profile::kMeasurementWriter)),
        star(p.createWriter<StarTrackerAttitudePubSubType>(bus::topic::kStarTracker,
                                                           bus::profile::kMeasurementWriter)) {}
  bool matched() const {
    return imu.matchedReaders() && obs.matchedReaders() && fix.matchedReaders() &&
           star.matchedReaders();
  }
  bus::Writer<ImuIncrement> imu;
  bus::Writer<GnssObservationEpoch> obs;
  bus::Writer<GnssFix> fix;
  bus::Writer<StarTrackerAttitude> star;
};

/// The simulator's default vehicle at the place and time filterConfig() starts the filter:
/// 36.5 N, 127.5 E, 100 m, GPS time 1.4e18 ns.
/// The seed-000 fault loop's three configuration files in `dir` for `domain`: the aircraft
/// scenario (or another seed-000 scenario of sim/scenarios) with `sim_extra` (timing, faults),
/// the tightly coupled filter writing every solution, the fault manager as shipped.
struct Seed000Loop {
  std::string sim, filter, fault_manager;
};
/// `filter` and `fault_manager` name files under config/ (without .yaml).
inline Seed000Loop writeSeed000Loop(const std::filesystem::path& dir, int domain,
                                    const std::string& sim_extra,
                                    const std::string& scenario = "seed000_aircraft",
                                    const std::string& filter = "filter_seed000_tc",
                                    const std::string& fault_manager = "fault_manager") {
  const std::string src = navbus::test_paths::sourceDir();
  const std::string dom = "domain_id: " + std::to_string(domain) + "\n";
  return {
      writeFile(dir / "sim.yaml",
                "extends: " + src + "/sim/scenarios/" + scenario + ".yaml\n" + dom + sim_extra),
      writeFile(dir / "filter.yaml",
                "extends: " + src + "/config/" + filter + ".yaml\n" + dom +
                    "solution_writer_profile: navbus_solution_writer_lossless\n"),
      writeFile(dir / "fm.yaml", "extends: " + src + "/config/" + fault_manager + ".yaml\n" + dom)};
}

/// `navbus offline` on the loop's files from the configured start into `dir`/offline (log
/// beside it), with `seed` when not empty; returns its exit code (nullopt: it did not end).
inline std::optional<int> runOffline(const Seed000Loop& loop, const std::filesystem::path& dir,
                                     const std::string& seed = "") {
  std::vector<std::string> args{"offline",
                                "--scenario",
                                loop.sim,
                                "--filter",
                                loop.filter,
                                "--fault-manager",
                                loop.fault_manager,
                                "--start",
                                "config",
                                "-o",
                                (dir / "offline").string()};
  if (!seed.empty()) args.insert(args.end(), {"--seed", seed});
  ChildProcess offline(navbus::test_paths::toolExe(), args, (dir / "offline.log").string());
  return offline.wait(std::chrono::seconds(180));
}

inline sim::ScenarioSource testScenarioSource() {
  sim::ScenarioConfig c;
  c.vehicle.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  c.start_time_ns = 1'400'000'000'000'000'000;
  return sim::ScenarioSource(c);
}

inline std::string filterConfig(int domain, std::uint32_t imu_id = 1, bool measurements = true) {
  std::string c = "domain_id: " + std::to_string(domain) +
                  "\nvehicle_id: 1\nsolution_rate_hz: 10\nsequencer_max_wait_s: 0.5\n"
                  "initial_state: {latitude_deg: 36.5, longitude_deg: 127.5, height_m: 100.0}\n"
                  "inputs:\n  imu: {id: " +
                  std::to_string(imu_id) + ", period_s: 0.01}\n";
  if (measurements) {
    c += "  gnss_observations: {id: 1, period_s: 1.0}\n  gnss_fix: {id: 1, period_s: 1.0}\n"
         "  star_tracker: {id: 1, period_s: 0.2}\n";
  }
  return c;
}

}  // namespace navbus::test
