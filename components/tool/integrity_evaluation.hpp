// Evaluation of the protection levels in Monte Carlo runs (`navbus montecarlo`, filters with an
// `integrity` block): at every solution with levels, the true horizontal and vertical position
// errors against the levels. An error beyond its level is misleading information when no
// alarm had been raised (no fault decision published before that solution). After an alarm it
// is counted apart, while the alarm stands (decision published, the fault manager's command not
// yet) and after the command answered it. Availability: the share of those solutions whose
// levels are both within the alert limits (INTEGRITY_AVAILABLE).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "offline_runner.hpp"

namespace navbus::tool {

struct IntegrityTally {
  std::uint64_t epochs{0};                  ///< solutions with protection levels
  std::uint64_t available{0};               ///< ... both within the alert limits
  std::uint64_t misleading{0};              ///< error beyond a level, no alarm raised yet
  std::uint64_t beyond_during_alarm{0};     ///< error beyond a level, alarm raised, not answered
  std::uint64_t beyond_after_answer{0};     ///< error beyond a level after the command answering it
  std::uint64_t misleading_unavailable{0};  ///< of `misleading`: while unavailable
  int runs{0}, runs_with_misleading{0};
  double max_ratio_h{0.0}, max_ratio_v{0.0};  ///< largest error / level
  std::vector<double> hpl_m, vpl_m;           ///< every level, for the quantiles

  /// Adds one run's solutions (OfflineResult::errors and the decisions' order).
  void add(const OfflineResult& r);
};

/// One table row per configuration (skips configurations without levels).
void printIntegrityTable(const std::vector<std::pair<std::string, IntegrityTally>>& rows);

}  // namespace navbus::tool
