// The filter participant's path without DDS: the IDL samples of seed 001 (IMU 200 Hz, GNSS fix
// 10 Hz, star tracker 5 Hz; loosely coupled) and of seed 000 (IMU 100 Hz, pseudoranges and fixes
// at 1 Hz; tightly coupled with protection levels) through FilterPipeline (validation, ordered
// merge, recovery history, engine, solution messages, low-latency output) as navbus-filter runs
// it, after a warm-up longer than the recovery history. Prints the time and heap allocations per
// IMU cycle in the steady state; exits 1 with --require-zero-allocations if any cycle of either
// case allocated.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "allocation_counter.hpp"
#include "filter_samples.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/filter_pipeline.hpp"

namespace {

using namespace navbus;

/// One case: the scenario's samples through a FilterPipeline with the filter file (the
/// low-latency output on, no fault monitor); prints its figures and returns the IMU cycles that
/// allocated after the warm-up.
std::uint64_t runCase(const std::string& label, const std::string& scenario,
                      const std::string& filter, int cycles) {
  const auto sim = sensor_sim::parseSimConfig(bus::loadYamlFile(scenario));
  YAML::Node filter_yaml = bus::loadYamlFile(filter);
  filter_yaml["low_latency_output"]["enabled"] = true;
  filter_yaml.remove("fault_monitor");  // no fault manager here: no judgement to wait for
  const nav_filter::FilterConfig cfg = nav_filter::parseFilterConfig(filter_yaml);
  const auto samples = bench::filterSamples(sim, cycles);

  bus::HealthCounters health("pipeline-benchmark");
  NavigationSolution last, last_fast;
  std::uint64_t solutions = 0, fast = 0;
  nav_filter::FilterPipeline pipeline(cfg, health,
                                      {[&](const NavigationSolution& s) {
                                         last = s;
                                         ++solutions;
                                       },
                                       nullptr,
                                       [&](const NavigationSolution& s) {
                                         last_fast = s;
                                         ++fast;
                                       }});
  // Warm-up: longer than the recovery history (cfg.recovery_history_ns), so its queues are at
  // their steady size.
  const auto warmup = static_cast<std::size_t>(
      std::min<double>(cycles / 2, 1.5 * 1e-9 * static_cast<double>(cfg.recovery_history_ns) /
                                       (1e-9 * static_cast<double>(sim.scenario.imu_period_ns))));
  std::uint64_t allocating_cycles = 0, allocations = 0;
  std::chrono::steady_clock::duration timed{};
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const std::uint64_t before = bench::g_allocations.load();
    const auto t0 = std::chrono::steady_clock::now();
    std::int64_t now = 0;
    for (const bench::FilterSample& s : samples[k]) now = std::max(now, bench::feed(pipeline, s));
    pipeline.pump(now);
    const auto t1 = std::chrono::steady_clock::now();
    if (k < warmup) continue;
    timed += t1 - t0;
    const std::uint64_t n = bench::g_allocations.load() - before;
    allocations += n;
    allocating_cycles += n > 0 ? 1 : 0;
  }
  const double measured = static_cast<double>(samples.size() - warmup);
  std::printf(
      "filter pipeline, %s, %zu IMU cycles after a %zu-cycle warm-up:\n"
      "  %.2f us per cycle, %.3f heap allocations per cycle, %llu of the cycles allocated "
      "(target 0)\n  solutions %llu, low-latency outputs %llu\n",
      label.c_str(), samples.size() - warmup, warmup,
      1e6 * std::chrono::duration<double>(timed).count() / measured,
      static_cast<double>(allocations) / measured,
      static_cast<unsigned long long>(allocating_cycles),
      static_cast<unsigned long long>(solutions), static_cast<unsigned long long>(fast));
  return allocating_cycles;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string root = argc > 1 ? argv[1] : ".";
  const int cycles = argc > 2 ? std::atoi(argv[2]) : 40000;
  const bool require_zero = argc > 3 && std::strcmp(argv[3], "--require-zero-allocations") == 0;
  std::uint64_t allocating = runCase(
      "seed 001 samples (IMU 200 Hz, GNSS fix 10 Hz, star tracker 5 Hz; loosely coupled)",
      root + "/sim/scenarios/seed001_leo.yaml", root + "/config/filter_seed001_lc.yaml", cycles);
  // The pseudorange path: its epochs' satellite lists are recycled from those the recovery
  // history forgets, once the history has gone round (the warm-up: 1.5 history spans).
  allocating += runCase(
      "seed 000 samples (IMU 100 Hz, pseudoranges and fix 1 Hz; tightly coupled, integrity)",
      root + "/sim/scenarios/seed000_aircraft.yaml", root + "/config/filter_seed000_tc.yaml",
      cycles);
  return require_zero && allocating > 0 ? 1 : 0;
}
