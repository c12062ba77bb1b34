// Evaluation of the protection levels in Monte Carlo runs (`navbus montecarlo`, filters with an
// `integrity` block): at every solution with levels, the true horizontal and vertical position
// errors against the levels. An alarm stands from a fault decision until the fault manager's
// next command (its answer; the end of the run if none comes): an error beyond its level
// while no alarm stands is misleading information, also after an answered alarm (the solution
// claims its levels again). Availability: the share of those solutions whose levels are both
// within the alert limits (INTEGRITY_AVAILABLE).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "navbus/evaluation/coverage.hpp"
#include "navbus/evaluation/offline_runner.hpp"

namespace navbus::evaluation {

struct IntegrityTally {
  std::uint64_t epochs{0};                   ///< solutions with protection levels
  std::uint64_t available{0};                ///< ... both within the alert limits
  std::uint64_t misleading{0};               ///< error beyond a level while no alarm stands
  std::uint64_t misleading_after_answer{0};  ///< of `misleading`: after an answered alarm
  std::uint64_t beyond_during_alarm{0};      ///< error beyond a level while an alarm stands
  std::uint64_t misleading_unavailable{0};   ///< of `misleading`: while unavailable
  int runs{0}, runs_with_misleading{0};
  std::vector<std::uint64_t> misleading_seeds;  ///< the runs with misleading information
  double max_ratio_h{0.0}, max_ratio_v{0.0};    ///< largest error / level
  std::vector<double> hpl_m, vpl_m;             ///< every level, for the quantiles

  /// Adds one run's solutions (OfflineResult::errors and the decisions' order).
  void add(const OfflineResult& r, std::uint64_t seed);
};

/// Whether the filter's own claims hold: its consistency monitor's alarms (on fault-free runs
/// the false-alarm rate, against its design probability), the epochs whose 3-D position
/// error exceeds 5 times the 3-D sigma while the solution says its covariance is valid, and
/// the published horizontal error against its own sigma_h at every epoch (coverage.hpp), with
/// the runs in which an unflagged epoch left 3 sigma_h ("inside 3 sigma throughout").
struct HonestyTally {
  core::ConsistencyCounters consistency;  ///< summed over the runs
  double design_probability{0.0};
  std::uint64_t epochs{0}, flagged{0};  ///< solutions, of them covariance_valid false
  std::uint64_t unflagged_beyond_5_sigma{0};
  int runs{0}, runs_unflagged_beyond_5_sigma{0};
  double max_unflagged_ratio{0.0};  ///< largest 3-D error / 3-D sigma, unflagged epochs
  CoverageTally coverage_h;         ///< every epoch with a finite error and sigma
  int runs_unflagged_beyond_3_sigma_h{0};
  std::vector<double>
      first_beyond_3_sigma_h_s;  ///< of those runs: the first such epoch [s from start]

  void add(const OfflineResult& r, double design_probability);
};
void printHonestyTable(const std::vector<std::pair<std::string, HonestyTally>>& rows);

/// One table row per configuration (skips configurations without levels).
void printIntegrityTable(const std::vector<std::pair<std::string, IntegrityTally>>& rows);

}  // namespace navbus::evaluation
