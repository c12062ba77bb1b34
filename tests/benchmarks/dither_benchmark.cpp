// Cost of the dither monitor (seed 003): 6 channels at 2400 Hz against the real-time budget
// (the data's own duration: the target is < 1 % of one core) and against the inertial
// mechanization of the same data's increments in the same run; heap allocations in the steady
// state (counted by replacing operator new). Prints medians of several passes; asserts nothing
// about time (a busy machine is slower, not wrong).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "allocation_counter.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/core/engine/navigation_engine.hpp"
#include "navbus/core/integrity/dither_monitor.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/scenario_source.hpp"

namespace {
namespace core = navbus::core;
using Clock = std::chrono::steady_clock;

struct RawSample {
  std::int64_t time_ns;
  Eigen::Vector3d f, w;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : "sim/scenarios";
  const int seconds = argc > 2 ? std::stoi(argv[2]) : 60;
  const auto sim = navbus::sensor_sim::parseSimConfig(
      navbus::bus::loadYamlFile(dir + "/seed003_laser_ins_moving.yaml"));
  navbus::sim::ScenarioSource src(sim.scenario);
  std::vector<RawSample> raw;
  std::vector<core::ImuIncrement> increments;
  const int frames = seconds * static_cast<int>(1'000'000'000 / sim.scenario.imu_period_ns);
  for (int k = 0; k < frames; ++k) {
    const auto fr = src.next();
    for (std::size_t i = 0; i < fr.raw.samples.size(); ++i) {
      raw.push_back({fr.raw.first_time_ns + static_cast<std::int64_t>(i) * 416667LL,
                     fr.raw.samples[i].specific_force_b_mps2,
                     fr.raw.samples[i].angular_rate_b_radps});
    }
    core::ImuIncrement inc;
    inc.time_ns = fr.increment.time_ns;
    inc.interval_s = fr.increment.interval_s;
    inc.delta_vel_b_mps = fr.increment.delta_vel_b_mps;
    inc.delta_angle_b_rad = fr.increment.delta_angle_b_rad;
    increments.push_back(inc);
  }
  std::vector<double> dither_s, mech_s;
  double allocs_per_window = 0.0;
  std::uint64_t windows = 0;
  for (int pass = 0; pass < 5; ++pass) {
    core::DitherMonitor m(core::DitherMonitorConfig{});
    // Steady state: allocations counted after the first window.
    std::size_t k = 0;
    const auto t0 = Clock::now();
    for (; k < raw.size() && m.counters().windows == 0; ++k)
      m.addSample(raw[k].time_ns, raw[k].f, raw[k].w);
    const std::uint64_t a0 = navbus::bench::g_allocations.load();
    const std::uint64_t w0 = m.counters().windows;
    for (; k < raw.size(); ++k) m.addSample(raw[k].time_ns, raw[k].f, raw[k].w);
    const std::uint64_t a1 = navbus::bench::g_allocations.load();
    const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
    dither_s.push_back(elapsed);
    windows = m.counters().windows;
    allocs_per_window = static_cast<double>(a1 - a0) / static_cast<double>(windows - w0);
    core::EngineConfig ec;
    ec.initial_state = navbus::sim::ScenarioSource(sim.scenario).truth();
    core::NavigationEngine engine(ec);
    const auto t1 = Clock::now();
    for (const auto& inc : increments) engine.addImu(inc);
    mech_s.push_back(std::chrono::duration<double>(Clock::now() - t1).count());
  }
  const double d = median(dither_s), mech = median(mech_s);
  std::printf(
      "dither monitor, seed003_laser_ins_moving, %d s of raw data (%zu samples x 6 "
      "channels at 2400 Hz, %llu windows of 512, hop 128), median of 5 passes:\n",
      seconds, raw.size(), static_cast<unsigned long long>(windows));
  std::printf("  monitor       %8.4f s  = %.3f %% of one core in real time (target < 1 %%)\n", d,
              100.0 * d / seconds);
  std::printf("  mechanization %8.4f s  (100 Hz increments + error-state covariance, same data)\n",
              mech);
  std::printf(
      "  ratio monitor / mechanization = %.2f; heap allocations per window %.3f "
      "(the monitor's own, constructor excluded: %s)\n",
      d / mech, allocs_per_window, allocs_per_window == 0.0 ? "none" : "SOME");
  return allocs_per_window == 0.0 ? 0 : 1;
}
