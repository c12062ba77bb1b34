// Cost of the GLR monitor (seed 000 eqs. 6-16) per GNSS epoch against the tightly coupled
// filter's own cost in the same run: the filter's measurement update of the epoch and its
// IMU cycle (mechanization + covariance), with M onsets and 4 and 12 satellites; heap
// allocations per GLR epoch (counted by replacing operator new). Prints medians over the
// epochs; asserts nothing about time (a busy machine is slower, not wrong).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include "allocation_counter.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/core/engine/navigation_engine.hpp"
#include "navbus/core/integrity/glr.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/scenario_source.hpp"

namespace {

namespace core = navbus::core;
using Clock = std::chrono::steady_clock;

double us(Clock::duration d) {
  return std::chrono::duration<double, std::micro>(d).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// The filter's epoch diagnostics as the GLR's input (what the bus conversion does).
void toGlrEpoch(const core::EpochDiagnostics& d, std::int64_t time_ns, core::GlrEpoch& e) {
  const auto m = d.h.rows();
  e.time_ns = time_ns;
  e.rows = static_cast<int>(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    e.sv_id[static_cast<std::size_t>(r)] = d.sv_ids[static_cast<std::size_t>(r)];
    e.is_rate[static_cast<std::size_t>(r)] = d.is_rate[static_cast<std::size_t>(r)];
  }
  e.innovation = d.innovation;
  e.innovation_cov = d.innovation_cov;
  e.h = d.h;
  e.k = d.k;
  e.phi = d.phi;
}

struct Figures {
  double satellites{0};
  double imu_cycle_us{0}, update_us{0}, glr_us{0}, glr_allocs{0};
  int epochs{0};
};

Figures run(const navbus::sim::ScenarioConfig& scenario, int seconds, int window) {
  navbus::sim::ScenarioSource src(scenario);
  core::EngineConfig cfg;
  cfg.aiding = core::AidingMode::kTightlyCoupled;
  cfg.tuning.gravity = scenario.gravity;
  cfg.tuning.pos_sigma_m = 40.0;
  cfg.tuning.accel_bias_sigma_mps2 = 1e-2;
  cfg.tuning.gyro_bias_sigma_radps = 5e-6;
  cfg.initial_state = src.truth();
  core::NavigationEngine engine(cfg);
  core::GlrConfig gc;
  gc.window = window;
  core::GlrMonitor glr(gc);
  core::GlrEpoch epoch;
  std::vector<double> imu, update, glr_us;
  std::uint64_t allocs = 0, sats = 0;
  const auto n =
      static_cast<int>(static_cast<std::int64_t>(seconds) * 1'000'000'000 / scenario.imu_period_ns);
  for (int i = 0; i < n; ++i) {
    const auto f = src.next();
    auto t0 = Clock::now();
    engine.addImu(f.increment);
    imu.push_back(us(Clock::now() - t0));
    if (!f.has_gnss) continue;
    std::vector<core::SatelliteObservation> obs;
    for (const auto& m : f.gnss.satellites) {
      obs.push_back({m.sv_id, m.sat_pos_ecef_m, m.sat_vel_ecef_mps,
                     m.pseudorange_m + m.sat_clock_correction_m,
                     m.pseudorange_rate_mps + m.sat_clock_drift_mps, m.pseudorange_sigma_m,
                     m.pseudorange_rate_sigma_mps});
    }
    t0 = Clock::now();
    const bool fused = engine.addGnssEpoch(f.increment.time_ns, obs);
    const double update_time = us(Clock::now() - t0);
    if (!fused) continue;
    toGlrEpoch(engine.lastEpoch(), engine.state().time_ns, epoch);
    const std::uint64_t a0 = navbus::bench::g_allocations.load();
    t0 = Clock::now();
    glr.update(epoch);
    const double glr_time = us(Clock::now() - t0);
    if (i < n / 5) continue;  // warm-up: the window fills, the filter converges
    if (static_cast<int>(obs.size()) < scenario.gnss.max_satellites &&
        scenario.gnss.fixed_satellites == 0)
      continue;  // the 12-satellite case: full epochs only
    allocs += navbus::bench::g_allocations.load() - a0;
    update.push_back(update_time);
    glr_us.push_back(glr_time);
    sats += obs.size();
  }
  Figures out;
  out.epochs = static_cast<int>(glr_us.size());
  out.satellites = out.epochs ? static_cast<double>(sats) / out.epochs : 0.0;
  out.imu_cycle_us = median(imu);
  out.update_us = median(update);
  out.glr_us = median(glr_us);
  out.glr_allocs = out.epochs ? static_cast<double>(allocs) / out.epochs : 0.0;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : "sim/scenarios";
  const int seconds = argc > 2 ? std::atoi(argv[2]) : 300;
  auto load = [&](const char* file) {
    return navbus::sensor_sim::parseSimConfig(navbus::bus::loadYamlFile(dir + "/" + file)).scenario;
  };
  std::printf(
      "GLR cost per GNSS epoch (%d s of data, medians over the epochs after warm-up): seed 000 "
      "aircraft with its 4 satellites; 12 satellites: seed 001 LEO (10 Hz GPS, mask -20 deg)\n",
      seconds);
  std::printf("%-30s %6s %4s %12s %14s %10s %12s %12s %12s\n", "configuration", "sats", "M",
              "IMU cycle us", "TC update us", "GLR us", "GLR/update", "GLR/IMU cyc", "GLR allocs");
  struct Case {
    const char* name;
    const char* file;
    int window;
  };
  for (const Case c : {Case{"seed 000: 4 satellites", "seed000_aircraft.yaml", 20},
                       Case{"seed 001 LEO: 12 satellites", "seed001_leo.yaml", 20},
                       Case{"seed 001 LEO: 12 satellites", "seed001_leo.yaml", 40}}) {
    auto s = load(c.file);
    s.gnss.max_satellites = 12;
    // From 500 km the GPS satellites down to about -20 deg of elevation are above the Earth's
    // limb: 12 in view.
    if (s.orbit) s.gnss.elevation_mask_rad = -20.0 * M_PI / 180.0;
    const Figures f = run(s, seconds, c.window);
    std::printf("%-30s %6.1f %4d %12.2f %14.2f %10.2f %12.2f %12.2f %12.3f\n", c.name, f.satellites,
                c.window, f.imu_cycle_us, f.update_us, f.glr_us, f.glr_us / f.update_us,
                f.glr_us / f.imu_cycle_us, f.glr_allocs);
  }
  std::printf("target: GLR <= 50 us per epoch with M = 20 and 12 satellites\n");
  return 0;
}
