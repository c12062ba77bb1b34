// Cost per filter cycle of each fusion structure (seed 001 table 6 measured 0.22-0.23 ms per
// cycle in their simulation), as ratios to the bare mechanization measured in the same run, and
// heap allocations per cycle in the steady state (counted by replacing operator new).
// Prints figures; asserts nothing about time (a busy machine is slower, not wrong).
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include "allocation_counter.hpp"
#include "benchmark_args.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/core/engine/navigation_engine.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/scenario_source.hpp"

namespace {

namespace core = navbus::core;

struct Input {
  core::ImuIncrement inc;
  bool has_fix{false}, has_star{false}, has_epoch{false};
  core::GnssFixMeasurement fix;
  core::StarAttitudeMeasurement star;
  std::vector<core::SatelliteObservation> sats;
};

std::vector<Input> makeInputs(const navbus::sim::ScenarioConfig& c, int n) {
  navbus::sim::ScenarioSource src(c);
  std::vector<Input> out(static_cast<std::size_t>(n));
  for (auto& in : out) {
    const auto f = src.next();
    in.inc = f.increment;
    if (f.has_gnss) {
      in.has_fix = in.has_epoch = true;
      in.fix = {f.fix.time_ns, f.fix.position, f.fix.vel_ned_mps, f.fix.pos_sigma_ned_m,
                f.fix.vel_sigma_ned_mps};
      for (const auto& m : f.gnss.satellites) {
        in.sats.push_back({m.sv_id, m.sat_pos_ecef_m, m.sat_vel_ecef_mps,
                           m.pseudorange_m + m.sat_clock_correction_m,
                           m.pseudorange_rate_mps + m.sat_clock_drift_mps, m.pseudorange_sigma_m,
                           m.pseudorange_rate_sigma_mps});
      }
    }
    if (f.has_star_tracker) {
      in.has_star = true;
      in.star = {f.star_tracker.time_ns, f.star_tracker.q_b_to_i, f.star_tracker.sigma_b_rad};
    }
  }
  return out;
}

struct Result {
  double us_per_cycle;
  double allocations_per_cycle;
  std::uint64_t aligning_cycles;  ///< increments the alignment took before the filter started
};

Result run(core::EngineConfig cfg, const std::vector<Input>& inputs, bool aid) {
  core::NavigationEngine engine(cfg);
  const std::size_t warmup = inputs.size() / 10;
  std::uint64_t alloc0 = 0;
  auto t0 = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (i == warmup) {
      alloc0 = navbus::bench::g_allocations.load();
      t0 = std::chrono::steady_clock::now();
    }
    const Input& in = inputs[i];
    engine.addImu(in.inc);
    if (!aid) continue;
    if (in.has_epoch && cfg.aiding == core::AidingMode::kTightlyCoupled)
      engine.addGnssEpoch(in.inc.time_ns, in.sats);
    if (in.has_fix) engine.addGnssFix(in.fix);
    if (in.has_star) engine.addStarAttitude(in.star);
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cycles = static_cast<double>(inputs.size() - warmup);
  return {1e6 * s / cycles,
          static_cast<double>(navbus::bench::g_allocations.load() - alloc0) / cycles,
          engine.counters().imu_aligning};
}

/// An engine configuration for a scenario's IMU period and gravity, started at its truth.
core::EngineConfig configFor(const navbus::sim::ScenarioConfig& c, double imu_period_s) {
  core::EngineConfig cfg;
  cfg.tuning.gravity = c.gravity;
  cfg.imu_period_s = imu_period_s;
  navbus::sim::ScenarioSource s(c);
  cfg.initial_state = s.truth();
  return cfg;
}

navbus::sim::ScenarioConfig scenarioFile(const std::string& path) {
  return navbus::sensor_sim::parseSimConfig(navbus::bus::loadYamlFile(path)).scenario;
}

void printRow(const char* name, const Result& r, const Result& base) {
  std::printf("%-44s %10.2f %8.3f %14.3f %9llu\n", name, r.us_per_cycle,
              r.us_per_cycle / base.us_per_cycle, r.allocations_per_cycle,
              static_cast<unsigned long long>(r.aligning_cycles));
}

/// Seed 000 (navigation-grade IMU at 100 Hz, 1 Hz pseudoranges, 500 s at rest first): the
/// tightly coupled filter from a configured state against the same filter aligning itself
/// (gyrocompassing, then fine alignment) and with protection levels (issue target: <= 1.2).
void integrityAndAlignment(const std::string& dir, int n) {
  const auto aircraft = scenarioFile(dir + "/seed000_aircraft.yaml");
  const auto inputs = makeInputs(aircraft, n);
  core::EngineConfig cfg = configFor(aircraft, 0.01);
  cfg.aiding = core::AidingMode::kTightlyCoupled;
  std::printf("\nseed 000 inputs, %d IMU cycles at 100 Hz (pseudoranges 1 Hz), tightly coupled\n",
              n);
  std::printf("%-44s %10s %8s %14s %9s\n", "configuration", "us/cycle", "ratio", "allocs/cycle",
              "aligning");
  const Result base = run(cfg, inputs, true);
  printRow("configured start (base)", base, base);
  core::EngineConfig aligned = cfg;
  aligned.start = core::StartSource::kAligned;
  printRow("aligned start (alignment, then the filter)", run(aligned, inputs, true), base);
  core::EngineConfig integrity = cfg;
  integrity.integrity.enabled = true;
  printRow("configured start + protection levels", run(integrity, inputs, true), base);
  integrity.start = core::StartSource::kAligned;
  printRow("aligned start + protection levels", run(integrity, inputs, true), base);
}

/// The benchmark: the scenarios in `dir`, `count` IMU cycles or seconds of data.
int benchmark(const std::string& dir, int n) {
  const auto leo = scenarioFile(dir + "/seed001_leo.yaml");
  const auto inputs = makeInputs(leo, n);
  core::EngineConfig cfg = configFor(leo, 0.005);
  cfg.aiding = core::AidingMode::kInertialOnly;
  const Result base = run(cfg, inputs, false);
  std::printf("seed 001 inputs, %d IMU cycles at 200 Hz (GPS 10 Hz, star tracker 5 Hz)\n", n);
  std::printf("%-36s %10s %8s %14s\n", "configuration", "us/cycle", "ratio", "allocs/cycle");
  std::printf("%-36s %10.2f %8.2f %14.3f\n", "mechanization + covariance (base)", base.us_per_cycle,
              1.0, base.allocations_per_cycle);
  core::EngineConfig base_lazy = cfg;  // the covariance every 0.1 s (the solution epochs)
  base_lazy.tuning.covariance_period_s = 0.1;
  const Result lazy = run(base_lazy, inputs, false);
  std::printf("%-36s %10.2f %8.2f %14.3f\n", "mechanization + covariance 0.10 s", lazy.us_per_cycle,
              lazy.us_per_cycle / base.us_per_cycle, lazy.allocations_per_cycle);
  cfg.aiding = core::AidingMode::kLooselyCoupled;
  cfg.use_star_tracker = true;
  for (auto [name, fusion] :
       {std::pair{"loosely coupled, centralized", core::FusionStructure::kCentralized},
        std::pair{"loosely coupled, federated", core::FusionStructure::kFederated},
        std::pair{"loosely coupled, adaptive", core::FusionStructure::kAdaptive}}) {
    cfg.fusion = fusion;
    const Result r = run(cfg, inputs, true);
    std::printf("%-36s %10.2f %8.2f %14.3f\n", name, r.us_per_cycle,
                r.us_per_cycle / base.us_per_cycle, r.allocations_per_cycle);
  }
  cfg.aiding = core::AidingMode::kTightlyCoupled;
  cfg.use_star_tracker = false;
  cfg.fusion = core::FusionStructure::kCentralized;
  const Result tc = run(cfg, inputs, true);
  std::printf("%-36s %10.2f %8.2f %14.3f\n", "tightly coupled (pseudoranges)", tc.us_per_cycle,
              tc.us_per_cycle / base.us_per_cycle, tc.allocations_per_cycle);
  // The covariance propagated over up to 0.05 s and 0.1 s at once (FilterTuning::
  // covariance_period_s); the solution epochs (10 Hz) and the 10 Hz epochs settle it too.
  for (const double period_s : {0.05, 0.1}) {
    core::EngineConfig lazy_tc = cfg;
    lazy_tc.tuning.covariance_period_s = period_s;
    const Result r = run(lazy_tc, inputs, true);
    const std::string name =
        "tightly coupled, covariance " + std::to_string(period_s).substr(0, 4) + " s";
    std::printf("%-36s %10.2f %8.2f %14.3f\n", name.c_str(), r.us_per_cycle,
                r.us_per_cycle / base.us_per_cycle, r.allocations_per_cycle);
  }
  integrityAndAlignment(dir, n);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return navbus::bench::benchmarkMain(argc, argv, 40000, "IMU_CYCLES", benchmark);
}
