#include "navbus/evaluation/integrity_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <navbus_idl/Navigation.h>

namespace navbus::evaluation {

namespace {

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

void IntegrityTally::add(const OfflineResult& r, std::uint64_t seed) {
  ++runs;
  // Alarms: from each decision to the first command after it (the fault manager's answer; no
  // answer: to the end of the run). Outside them the solution claims its levels.
  const std::size_t none = r.errors.size();
  std::vector<std::pair<std::size_t, std::size_t>> alarms;
  for (std::size_t d : r.decision_after_solutions) {
    std::size_t answer = none;
    for (std::size_t c : r.command_after_solutions) {
      if (c >= d) {
        answer = c;
        break;
      }
    }
    alarms.emplace_back(d, answer);
  }
  const auto alarmed = [&alarms](std::size_t i) {
    for (const auto& [from, to] : alarms)
      if (i >= from && i < to) return true;
    return false;
  };
  const std::size_t first_decision =
      r.decision_after_solutions.empty() ? none : r.decision_after_solutions.front();
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
    if (alarmed(i)) {
      ++beyond_during_alarm;
    } else {
      ++misleading;
      misleading_unavailable += e.integrity == navbus::INTEGRITY_UNAVAILABLE ? 1 : 0;
      misleading_after_answer += i >= first_decision ? 1 : 0;
      run_misleading = true;
    }
  }
  if (run_misleading) {
    ++runs_with_misleading;
    misleading_seeds.push_back(seed);
  }
}

void HonestyTally::add(const OfflineResult& r, double probability) {
  design_probability = probability;
  consistency.epochs_tested += r.consistency.epochs_tested;
  consistency.epochs_inconsistent += r.consistency.epochs_inconsistent;
  consistency.alarms += r.consistency.alarms;
  consistency.reinitialisations += r.consistency.reinitialisations;
  consistency.nis_sum += r.consistency.nis_sum;
  consistency.rows += r.consistency.rows;
  ++runs;
  std::uint64_t beyond = 0;
  bool left_3_sigma_h = false;
  for (const EpochError& e : r.errors) {
    ++epochs;
    const double error_h = e.pos_ned_m.head<2>().norm();
    const double sigma_h = e.pos_sigma_ned_m.head<2>().norm();
    if (std::isfinite(error_h) && std::isfinite(sigma_h)) {
      coverage_h.add(error_h, sigma_h, e.covariance_valid);
      if (!left_3_sigma_h && e.covariance_valid && !(error_h <= 3.0 * sigma_h)) {
        left_3_sigma_h = true;
        first_beyond_3_sigma_h_s.push_back(
            1e-9 * static_cast<double>(e.time_ns - r.errors.front().time_ns));
      }
    }
    if (!e.covariance_valid) {
      ++flagged;
      continue;
    }
    const double sigma = e.pos_sigma_ned_m.norm();
    if (!(sigma > 0.0)) continue;
    const double ratio = e.pos_ned_m.norm() / sigma;
    max_unflagged_ratio = std::max(max_unflagged_ratio, ratio);
    beyond += ratio > 5.0 ? 1 : 0;
  }
  unflagged_beyond_5_sigma += beyond;
  runs_unflagged_beyond_5_sigma += beyond > 0 ? 1 : 0;
  runs_unflagged_beyond_3_sigma_h += left_3_sigma_h ? 1 : 0;
}

void printHonestyTable(const std::vector<std::pair<std::string, HonestyTally>>& rows) {
  std::printf(
      "\nhonesty: the consistency monitor (share of tested epochs whose window failed, against "
      "its design probability) and epochs whose 3-D position error exceeds 5 x the 3-D sigma "
      "while covariance_valid\n%-34s %8s %10s %12s %10s %8s %8s %9s %14s %10s\n",
      "configuration", "NIS/row", "tested", "inconsistent", "rate", "design", "alarms", "flagged",
      "runs >5 sigma", "max err/s");
  for (const auto& [label, t] : rows) {
    const double rate = t.consistency.epochs_tested > 0
                            ? static_cast<double>(t.consistency.epochs_inconsistent) /
                                  static_cast<double>(t.consistency.epochs_tested)
                            : 0.0;
    const double nis_per_row = t.consistency.rows > 0
                                   ? t.consistency.nis_sum / static_cast<double>(t.consistency.rows)
                                   : 0.0;
    std::printf("%-34s %8.3f %10llu %12llu %10.2e %8.0e %8llu %9llu %8d of %3d %10.2f\n",
                label.c_str(), nis_per_row,
                static_cast<unsigned long long>(t.consistency.epochs_tested),
                static_cast<unsigned long long>(t.consistency.epochs_inconsistent), rate,
                t.design_probability, static_cast<unsigned long long>(t.consistency.alarms),
                static_cast<unsigned long long>(t.flagged), t.runs_unflagged_beyond_5_sigma, t.runs,
                t.max_unflagged_ratio);
  }
  std::printf(
      "\ncoverage: the published horizontal error e against its own sigma_h, every epoch of "
      "every run\n%s",
      coverageHeader().c_str());
  for (const auto& [label, t] : rows)
    std::printf("%s", coverageRow(label, t.coverage_h, true).c_str());
  std::printf("%s", coverageFooter().c_str());
  for (const auto& [label, t] : rows) {
    const double epochs = static_cast<double>(t.coverage_h.epochs());
    std::printf(
        "%s: runs with an unflagged epoch beyond 3 sigma_h: %d of %d (the first at %s s); epochs "
        "beyond 3 sigma_h %.0f (a consistent filter: %.0f)\n",
        label.c_str(), t.runs_unflagged_beyond_3_sigma_h, t.runs,
        fmt::format("{:.1f}", fmt::join(t.first_beyond_3_sigma_h_s, ", ")).c_str(),
        epochs * (1.0 - t.coverage_h.insideShare(3)), epochs * (1.0 - consistentShare(3)));
  }
}

void printIntegrityTable(const std::vector<std::pair<std::string, IntegrityTally>>& rows) {
  bool any = false;
  for (const auto& [label, t] : rows) any = any || t.epochs > 0;
  if (!any) return;
  std::printf(
      "\nintegrity: protection levels against the true position error, every solution with "
      "levels\n  (misleading: error beyond a level while no alarm stands, an alarm standing from "
      "a decision to the fault manager's next command; of them after an answered alarm; "
      "alarmed: beyond a level while one stands; available: both levels within the alert "
      "limits; unavail.: of the misleading, while a level exceeded its alert limit)\n");
  std::printf("%-34s %9s %9s %9s %9s %9s %10s %10s %12s %8s %8s %8s\n", "configuration", "epochs",
              "available", "HPL p50 m", "HPL p99", "VPL p50 m", "max eH/HPL", "max eV/VPL",
              "misleading", "answered", "unavail.", "alarmed");
  for (const auto& [label, t] : rows) {
    if (t.epochs == 0) continue;
    const double n = static_cast<double>(t.epochs);
    std::printf(
        "%-34s %9llu %8.2f%% %9.2f %9.2f %9.2f %10.3f %10.3f %5llu (%d run%s) %8llu %8llu %8llu\n",
        label.c_str(), static_cast<unsigned long long>(t.epochs),
        100.0 * static_cast<double>(t.available) / n, quantile(t.hpl_m, 0.5),
        quantile(t.hpl_m, 0.99), quantile(t.vpl_m, 0.5), t.max_ratio_h, t.max_ratio_v,
        static_cast<unsigned long long>(t.misleading), t.runs_with_misleading,
        t.runs_with_misleading == 1 ? "" : "s",
        static_cast<unsigned long long>(t.misleading_after_answer),
        static_cast<unsigned long long>(t.misleading_unavailable),
        static_cast<unsigned long long>(t.beyond_during_alarm));
    if (!t.misleading_seeds.empty()) {
      std::printf("  seeds with misleading information:");
      for (std::uint64_t s : t.misleading_seeds)
        std::printf(" %llu", static_cast<unsigned long long>(s));
      std::printf("\n");
    }
  }
}

}  // namespace navbus::evaluation
