// `navbus offline` and `navbus montecarlo`: the offline runner driven from the command line,
// files and summary tables.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "navbus/evaluation/offline_runner.hpp"

namespace navbus::evaluation {

struct OfflineOptions {
  std::string scenario;
  std::string filter;
  std::uint64_t seed{0};   ///< 0: the scenario's own
  double duration_s{0.0};  ///< 0: the scenario's
  std::string out_dir;
  std::string fault_manager;  ///< navbus-fault-manager YAML: run the fault pipeline too
  bool align{true};  ///< align from the inputs even when the filter YAML has an initial_state
};

/// Writes solution.csv, truth.csv and error.csv (columns in docs/tools.md); returns an exit code.
int runOfflineCommand(const OfflineOptions& o);

struct MonteCarloOptions {
  std::string scenario;
  std::vector<std::string> filters;   ///< one table row (or more, see below) per file
  std::vector<std::string> fusions;   ///< optional: override `fusion` of each filter file
  std::vector<std::string> policies;  ///< optional: override multi_dimensional.policy
  int runs{10};
  std::uint64_t first_seed{1};
  double duration_s{0.0};
  double from_s{0.0};          ///< statistics from this many seconds after the start
  bool perturb_initial{true};  ///< draw the initial state from the filter's initial sigmas
  /// Align from the inputs (every filter as if it had no initial_state); filters without an
  /// initial_state align anyway.
  bool align{true};
  std::vector<double> recovery_after_s;  ///< convergence times after these instants
  double recovery_threshold_m{3.0};      ///< horizontal position error that counts as converged
  double recovery_window_s{15.0};        ///< ... and must stay below it this long
  std::string fault_manager;  ///< navbus-fault-manager YAML: run and evaluate the fault pipeline
  int threads{0};             ///< parallel runs (0: one per core)
  /// Directory for nees.csv (average NEES per epoch and its band, per configuration) and,
  /// with a fault manager, faults.csv (one row per run); empty: tables only.
  std::string csv_dir;
};

int runMonteCarloCommand(const MonteCarloOptions& o);

/// Seconds after t0 until the horizontal position error stays below threshold_m for window_s
/// (NaN when that does not happen within the window after t0).
double convergenceTime(const std::vector<EpochError>& errors, std::int64_t t0_ns,
                       double threshold_m, double window_s);

/// Quantile of the chi-square distribution (Boost.Math).
double chiSquareQuantile(double p, double dof);

}  // namespace navbus::evaluation
