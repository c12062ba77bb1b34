// Heap allocations on navbus-filter's processing thread from its first solution on: the
// participant's whole path (DDS take, validation, conversion, the pipeline, the writes of the
// low-latency output and of the solutions) with real Fast DDS participants in this process.
// navbus's own code must allocate nothing; what Fast DDS's writers allocate inside their write
// calls is counted apart and printed (navbus does not control it).
//
// The processing thread is this test's main thread, which runs a FilterNode exactly as
// navbus-filter's main() does (config/filter_latency.yaml: the IMU alone at 200 Hz, the
// low-latency output on; with a recovery history of 40 s); a second thread is the IMU (its own
// participant, writer and readers of both solution topics). malloc, calloc, realloc and the
// aligned allocators are replaced in this executable (every library's calls come here: Fast
// DDS's, Eigen's, the standard library's); they count the calls made on the main thread while
// counting is on, by call stack. Domain 119.
#include <dlfcn.h>
#include <execinfo.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <utility>

#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include <spdlog/spdlog.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/bus/participant.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/filter_node.hpp"
#include "test_paths.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace {

thread_local bool t_counting = false;
thread_local bool t_in_hook = false;
std::atomic<std::uint64_t> g_allocations{0};

/// Distinct allocation sites (by their call stack) with a count each; fixed storage: the hook
/// itself must not allocate.
constexpr int kSites = 128, kFrames = 14;
struct Site {
  void* frames[kFrames];
  int depth{0};
  std::uint64_t count{0};
};
Site g_sites[kSites];
int g_site_count = 0;
std::uint64_t g_unkept = 0;  ///< allocations at sites beyond kSites

void noteAllocation() {
  if (!t_counting || t_in_hook) return;
  t_in_hook = true;
  ++g_allocations;
  void* frames[kFrames];
  const int depth = backtrace(frames, kFrames);
  int k = 0;
  while (k < g_site_count &&
         !(g_sites[k].depth == depth && std::equal(frames, frames + depth, g_sites[k].frames)))
    ++k;
  if (k == g_site_count && g_site_count < kSites) {
    std::copy(frames, frames + depth, g_sites[k].frames);
    g_sites[k].depth = depth;
    ++g_site_count;
  }
  if (k < kSites) {
    ++g_sites[k].count;
  } else {
    ++g_unkept;
  }
  t_in_hook = false;
}

}  // namespace

extern "C" {
void* malloc(std::size_t n) {
  noteAllocation();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  noteAllocation();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  noteAllocation();
  return __libc_realloc(p, n);
}
void free(void* p) {
  __libc_free(p);
}
void* memalign(std::size_t alignment, std::size_t n) {
  noteAllocation();
  return __libc_memalign(alignment, n);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {
  noteAllocation();
  return __libc_memalign(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
  noteAllocation();
  *out = __libc_memalign(alignment, n);
  return *out != nullptr ? 0 : ENOMEM;
}
}

namespace {

using namespace navbus;
using Clock = std::chrono::steady_clock;
constexpr int kDomain = 119;
constexpr int kIncrements = 1200;  ///< 6 s of data at 200 Hz, written in real time
constexpr std::int64_t kPeriodNs = 5'000'000;

/// A user QoS file that turns Fast DDS's intraprocess delivery off (read after navbus's file,
/// whose library settings allow it for user data); removed at the end. Both participants live
/// in this process: with intraprocess delivery, Fast DDS would hand each sample to the other
/// participant's reader on the writing thread, which a filter and its IMU in two processes
/// never do.
struct QosFile {
  QosFile() {
    std::ofstream(path) << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                           "<dds xmlns=\"http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles\">\n"
                           "  <library_settings>\n"
                           "    <intraprocess_delivery>OFF</intraprocess_delivery>\n"
                           "  </library_settings>\n"
                           "  <profiles>\n"  // Fast DDS refuses a file without a profile
                           "    <participant profile_name=\"navbus_hot_path_test\"><rtps/>"
                           "</participant>\n"
                           "  </profiles>\n"
                           "</dds>\n";
  }
  ~QosFile() { std::remove(path.c_str()); }
  QosFile(const QosFile&) = delete;
  QosFile& operator=(const QosFile&) = delete;
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("navbus-hot-path-" + std::to_string(getpid()) + ".xml"))
                               .string();
};

bus::Participant::Options participantOptions(const std::string& name, const std::string& qos) {
  bus::Participant::Options options;
  options.dds.domain_id = kDomain;
  options.dds.name = name;
  options.dds.participant_profile = bus::profile::kParticipantLoopback;
  options.dds.qos_file = qos;
  return options;
}

/// The IMU of the filter under test, on its own thread and participant: writes the increments
/// of a level body at rest (config/filter_latency.yaml's position) every 5 ms of wall time, as
/// a 200 Hz IMU does, counts both outputs. As a sensor, it does not catch up after this process
/// was stopped (a stall): the next increment goes out one period after the late one.
class ImuThread {
 public:
  explicit ImuThread(std::string qos_file)
      : qos_file_(std::move(qos_file)), thread_([this] { run(); }) {}
  ~ImuThread() {
    stop_ = true;
    thread_.join();
  }
  ImuThread(const ImuThread&) = delete;
  ImuThread& operator=(const ImuThread&) = delete;
  std::atomic<int> low_latency{0}, solutions{0}, written{0};
  std::atomic<bool> done{false};

 private:
  void run() {
    bus::ShutdownSignal shutdown;
    bus::Participant::Options options = participantOptions("imu", qos_file_);
    options.publish_health = false;
    bus::Participant p(options, shutdown);
    auto imu = p.createWriter<ImuIncrementPubSubType>(bus::topic::kImuIncrement,
                                                      bus::profile::kSensorWriter);
    p.subscribe<NavigationSolutionPubSubType>(
        bus::topic::kNavSolutionLowLatency, bus::profile::kLowLatencySolutionReader,
        [&](const NavigationSolution&, const auto&) { ++low_latency; });
    p.subscribe<NavigationSolutionPubSubType>(
        bus::topic::kNavSolution, bus::profile::kSolutionReader,
        [&](const NavigationSolution&, const auto&) { ++solutions; });
    const auto match_end = Clock::now() + std::chrono::seconds(20);
    while (imu.matchedReaders() == 0 && Clock::now() < match_end && !stop_)
      p.spinOnce(std::chrono::milliseconds(10));
    const double lat = 36.5 * M_PI / 180.0, height = 100.0;
    core::ImuIncrement inc;
    inc.interval_s = 1e-9 * static_cast<double>(kPeriodNs);
    inc.delta_vel_b_mps = -core::earth::gravityNed(lat, height) * inc.interval_s;
    inc.delta_angle_b_rad = core::earth::omegaIeNed(lat) * inc.interval_s;
    const std::int64_t t0 = 1'400'000'000'000'000'000;
    auto next = Clock::now();
    for (int k = 0; k < kIncrements && !stop_; ++k) {
      while (Clock::now() < next) p.spinOnce(next - Clock::now());
      inc.time_ns = t0 + static_cast<std::int64_t>(k + 1) * kPeriodNs;
      imu.write(bus::toIdl(inc, 1, static_cast<std::uint64_t>(k + 1)));
      ++written;
      next = std::max(next, Clock::now()) + std::chrono::nanoseconds(kPeriodNs);
    }
    const auto drain_end = Clock::now() + std::chrono::seconds(10);
    int last = -1;
    while (low_latency != last && Clock::now() < drain_end && !stop_) {
      last = low_latency;
      p.spinOnce(std::chrono::milliseconds(200));
    }
    done = true;
    while (!stop_) p.spinOnce(std::chrono::milliseconds(10));
  }
  std::string qos_file_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// Whether a site's stack passes through Fast DDS (the library's own allocations on the write
/// path of a reliable writer, which navbus does not control).
bool insideFastDds(const Site& site) {
  for (int f = 0; f < site.depth; ++f) {
    Dl_info info;
    if (dladdr(site.frames[f], &info) != 0 && info.dli_fname != nullptr &&
        std::strstr(info.dli_fname, "libfastrtps") != nullptr)
      return true;
  }
  return false;
}

struct Split {
  std::uint64_t fast_dds{0}, navbus{0};
};

/// Adds up the sites inside and outside Fast DDS; prints the stacks of those outside.
Split splitSites() {
  Split split;
  for (int k = 0; k < g_site_count; ++k) {
    if (insideFastDds(g_sites[k])) {
      split.fast_dds += g_sites[k].count;
      continue;
    }
    split.navbus += g_sites[k].count;
    std::fprintf(stderr, "%llu allocation(s) on the processing thread outside Fast DDS at:\n",
                 static_cast<unsigned long long>(g_sites[k].count));
    backtrace_symbols_fd(g_sites[k].frames, g_sites[k].depth, STDERR_FILENO);
  }
  return split;
}

TEST(HotPathAllocations, NoneInNavbusOnTheProcessingThreadFromTheFirstSolutionOn) {
  void* warm[2];
  backtrace(warm, 2);  // loads the unwinder now, not inside the first counted allocation
  const QosFile qos;
  YAML::Node yaml =
      bus::loadYamlFile(std::string(test_paths::configDir()) + "/filter_latency.yaml");
  // With the recovery history that configuration leaves off (the demo's 40 s): its records
  // and snapshots are on the path too.
  yaml["recovery"]["history_s"] = 40;
  const nav_filter::FilterConfig config = nav_filter::parseFilterConfig(yaml);
  // navbus-filter's main() logs before it runs the node: spdlog's registry is made there, not
  // at the first warning on the processing thread (a stall of this process logs one).
  spdlog::info("hot path test: the filter on domain {}", kDomain);
  bus::ShutdownSignal shutdown;
  bus::Participant participant(participantOptions("navbus-filter", qos.path), shutdown);
  nav_filter::FilterNode node(participant, config);
  ImuThread imu(qos.path);

  const auto deadline = Clock::now() + std::chrono::seconds(60);
  while (imu.solutions == 0 && Clock::now() < deadline)
    participant.spinOnce(std::chrono::milliseconds(5));
  ASSERT_GT(imu.solutions.load(), 0) << "no solution within 60 s";
  const int written_before = imu.written;
  t_counting = true;
  while (!imu.done && Clock::now() < deadline) participant.spinOnce(std::chrono::milliseconds(5));
  t_counting = false;

  const int cycles = imu.written - written_before;
  const Split split = splitSites();
  std::printf(
      "processing thread, from the first solution on: %d IMU cycles (low-latency outputs "
      "received %d, solutions %d), %llu heap allocations: %llu in navbus's code, %llu inside "
      "Fast DDS's calls (%.1f per IMU cycle)\n",
      cycles, imu.low_latency.load(), imu.solutions.load(),
      static_cast<unsigned long long>(g_allocations.load()),
      static_cast<unsigned long long>(split.navbus),
      static_cast<unsigned long long>(split.fast_dds),
      cycles > 0 ? static_cast<double>(split.fast_dds) / cycles : 0.0);
  EXPECT_GT(cycles, kIncrements / 2);
  EXPECT_GE(imu.low_latency.load(), cycles);
  EXPECT_EQ(g_unkept, 0u) << "more allocation sites than kept: the split is partial";
  EXPECT_EQ(split.navbus, 0u);
}

}  // namespace
