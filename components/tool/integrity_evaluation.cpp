#include "integrity_evaluation.hpp"

#include <algorithm>
#include <cstdio>

#include <navbus_idl/Navigation.h>

namespace navbus::tool {

namespace {

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

void IntegrityTally::add(const OfflineResult& r) {
  ++runs;
  const std::size_t none = r.errors.size();
  const std::size_t first_alarm =
      r.decision_after_solutions.empty() ? none : r.decision_after_solutions.front();
  // The alarm is answered by the first command the fault manager sent after it.
  std::size_t answered = none;
  for (std::size_t c : r.command_after_solutions) {
    if (c >= first_alarm) {
      answered = c;
      break;
    }
  }
  bool run_misleading = false;
  for (std::size_t i = 0; i < r.errors.size(); ++i) {
    const EpochError& e = r.errors[i];
    const bool has_levels =
        e.integrity == navbus::INTEGRITY_AVAILABLE || e.integrity == navbus::INTEGRITY_UNAVAILABLE;
    if (!has_levels) continue;
    ++epochs;
    available += e.integrity == navbus::INTEGRITY_AVAILABLE ? 1 : 0;
    hpl_m.push_back(e.hpl_m);
    vpl_m.push_back(e.vpl_m);
    const double eh = e.pos_ned_m.head<2>().norm(), ev = std::abs(e.pos_ned_m.z());
    max_ratio_h = std::max(max_ratio_h, eh / e.hpl_m);
    max_ratio_v = std::max(max_ratio_v, ev / e.vpl_m);
    if (eh <= e.hpl_m && ev <= e.vpl_m) continue;
    if (i < first_alarm) {
      ++misleading;
      misleading_unavailable += e.integrity == navbus::INTEGRITY_UNAVAILABLE ? 1 : 0;
      run_misleading = true;
    } else if (i < answered) {
      ++beyond_during_alarm;
    } else {
      ++beyond_after_answer;
    }
  }
  runs_with_misleading += run_misleading ? 1 : 0;
}

void printIntegrityTable(const std::vector<std::pair<std::string, IntegrityTally>>& rows) {
  bool any = false;
  for (const auto& [label, t] : rows) any = any || t.epochs > 0;
  if (!any) return;
  std::printf(
      "\nintegrity: protection levels against the true position error, every solution with "
      "levels\n  (misleading: error beyond a level before any alarm; alarmed / answered: beyond "
      "a level after the first decision, before / after the command answering it; available: "
      "both levels within the alert limits)\n");
  std::printf("%-34s %9s %9s %9s %9s %9s %10s %10s %12s %8s %8s\n", "configuration", "epochs",
              "available", "HPL p50 m", "HPL p99", "VPL p50 m", "max eH/HPL", "max eV/VPL",
              "misleading", "alarmed", "answered");
  for (const auto& [label, t] : rows) {
    if (t.epochs == 0) continue;
    const double n = static_cast<double>(t.epochs);
    std::printf(
        "%-34s %9llu %8.2f%% %9.2f %9.2f %9.2f %10.3f %10.3f %5llu (%d run%s) %8llu %8llu\n",
        label.c_str(), static_cast<unsigned long long>(t.epochs),
        100.0 * static_cast<double>(t.available) / n, quantile(t.hpl_m, 0.5),
        quantile(t.hpl_m, 0.99), quantile(t.vpl_m, 0.5), t.max_ratio_h, t.max_ratio_v,
        static_cast<unsigned long long>(t.misleading), t.runs_with_misleading,
        t.runs_with_misleading == 1 ? "" : "s",
        static_cast<unsigned long long>(t.beyond_during_alarm),
        static_cast<unsigned long long>(t.beyond_after_answer));
  }
}

}  // namespace navbus::tool
