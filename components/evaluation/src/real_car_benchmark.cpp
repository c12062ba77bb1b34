#include "navbus/evaluation/real_car_benchmark.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "navbus/bus/app.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/core/gnss/gps_broadcast_ephemeris.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/evaluation/coverage.hpp"
#include "navbus/evaluation/recording_runner.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/importers/importer.hpp"
#include "navbus/importers/rtklib_pos.hpp"

namespace navbus::evaluation {

namespace {

namespace earth = core::earth;
constexpr auto kWeekNs = static_cast<std::int64_t>(core::gps::kSecondsPerWeek) * 1'000'000'000;
constexpr std::uint8_t kQualityFix = 1;

std::int64_t secondsOfWeekNs(std::int64_t time_ns) {
  return time_ns % kWeekNs;
}

/// The outage holding the epoch, or -1.
int outageOf(std::int64_t time_ns, const std::vector<Outage>& outages) {
  const std::int64_t sow_ns = secondsOfWeekNs(time_ns);
  for (std::size_t i = 0; i < outages.size(); ++i) {
    if (sow_ns >= std::llround(outages[i].start_sow * 1e9) &&
        sow_ns < std::llround(outages[i].end_sow * 1e9))
      return static_cast<int>(i);
  }
  return -1;
}

/// The antenna as the filter saw it at a solution epoch.
struct AntennaPoint {
  std::int64_t time_ns;
  earth::Geodetic position;
  Eigen::Vector3d vel_ned_mps;
  double sigma_h_m;  ///< sqrt(sigma_N^2 + sigma_E^2)
  double sigma_v_m;
  bool valid;  ///< the solution's covariance_valid (true where a run has no such flag)
  /// The solution's integrity and protection levels (NOT_MONITORED where a run has none).
  navbus::IntegrityState integrity{navbus::INTEGRITY_NOT_MONITORED};
  double hpl_m{0.0}, vpl_m{0.0};
};

AntennaPoint antennaOf(const navbus::NavigationSolution& s, const Eigen::Vector3d& lever_b) {
  const Eigen::Quaterniond q(s.q_b_to_n()[0], s.q_b_to_n()[1], s.q_b_to_n()[2], s.q_b_to_n()[3]);
  const earth::Geodetic imu{s.latitude_rad(), s.longitude_rad(), s.height_m()};
  const auto& sd = s.pos_sigma_ned_m();
  return {static_cast<std::int64_t>(s.time_gps_ns()),
          earth::offsetNed(imu, q * lever_b),
          Eigen::Vector3d(s.vel_ned_mps()[0], s.vel_ned_mps()[1], s.vel_ned_mps()[2]),
          std::hypot(sd[0], sd[1]),
          sd[2],
          s.covariance_valid(),
          s.integrity(),
          s.horizontal_protection_level_m(),
          s.vertical_protection_level_m()};
}

/// Horizontal error [m] of the antenna against a reference at its time, from the solutions
/// around it (linear in time between the two); nullopt outside the solutions.
struct Judged {
  double horizontal_m;
  double sigma_h_m;
  bool valid;              ///< covariance_valid of the solution(s) judged
  double vertical_m{0.0};  ///< |error| along the vertical [m]
  /// Integrity of the solution(s) judged: AVAILABLE only when each was, with the smaller
  /// levels (the stricter test of the error against them).
  navbus::IntegrityState integrity{navbus::INTEGRITY_NOT_MONITORED};
  double hpl_m{0.0}, vpl_m{0.0};
};

/// The integrity fields of a judgement from one solution, or from two (interpolated).
void takeIntegrity(const AntennaPoint& p, Judged& j) {
  j.integrity = p.integrity;
  j.hpl_m = p.hpl_m;
  j.vpl_m = p.vpl_m;
}
void takeIntegrity(const AntennaPoint& a, const AntennaPoint& b, Judged& j) {
  j.integrity = a.integrity == b.integrity ? a.integrity
                : (a.integrity == navbus::INTEGRITY_NOT_MONITORED ||
                   b.integrity == navbus::INTEGRITY_NOT_MONITORED)
                    ? navbus::INTEGRITY_NOT_MONITORED
                    : navbus::INTEGRITY_UNAVAILABLE;
  j.hpl_m = std::min(a.hpl_m, b.hpl_m);
  j.vpl_m = std::min(a.vpl_m, b.vpl_m);
}
std::optional<Judged> judge(const std::vector<AntennaPoint>& points, std::int64_t t,
                            const earth::Geodetic& reference) {
  const auto after =
      std::lower_bound(points.begin(), points.end(), t,
                       [](const AntennaPoint& p, std::int64_t v) { return p.time_ns < v; });
  if (after == points.end() || after == points.begin()) return std::nullopt;
  const AntennaPoint& b = *after;
  const AntennaPoint& a = *(after - 1);
  const double w = static_cast<double>(t - a.time_ns) / static_cast<double>(b.time_ns - a.time_ns);
  const Eigen::Vector3d ea = earth::differenceNed(a.position, reference);
  const Eigen::Vector3d eb = earth::differenceNed(b.position, reference);
  const Eigen::Vector3d e = (1.0 - w) * ea + w * eb;
  Judged j{e.head<2>().norm(), (1.0 - w) * a.sigma_h_m + w * b.sigma_h_m, a.valid && b.valid,
           std::abs(e.z())};
  takeIntegrity(a, b, j);
  return j;
}

/// Horizontal error [m] of the filter's solution once it took the fix of time t: the first
/// solution at or after t (the fix is fused at the increment that reaches its time), brought
/// back to t along its own velocity. Interpolating with the solution before t would score the
/// prediction the fix corrects (after an outage: the outage's end error, once more).
std::optional<Judged> judgeAfterFusion(const std::vector<AntennaPoint>& points, std::int64_t t,
                                       const earth::Geodetic& reference) {
  const auto at =
      std::lower_bound(points.begin(), points.end(), t,
                       [](const AntennaPoint& p, std::int64_t v) { return p.time_ns < v; });
  if (at == points.end() || at == points.begin()) return std::nullopt;
  const double back_s = 1e-9 * static_cast<double>(at->time_ns - t);
  const Eigen::Vector3d e =
      earth::differenceNed(at->position, reference) - at->vel_ned_mps * back_s;
  Judged j{e.head<2>().norm(), at->sigma_h_m, at->valid, std::abs(e.z())};
  takeIntegrity(*at, j);
  return j;
}

/// A solution of its own epochs (single point positioning): the one nearest t, within 20 ms.
std::optional<Judged> judgeNearest(const std::vector<AntennaPoint>& points, std::int64_t t,
                                   const earth::Geodetic& reference) {
  constexpr std::int64_t kToleranceNs = 20'000'000;
  const auto after =
      std::lower_bound(points.begin(), points.end(), t,
                       [](const AntennaPoint& p, std::int64_t v) { return p.time_ns < v; });
  const AntennaPoint* best = nullptr;
  if (after != points.end()) best = &*after;
  if (after != points.begin() && (best == nullptr || t - (after - 1)->time_ns < best->time_ns - t))
    best = &*(after - 1);
  if (best == nullptr || std::llabs(best->time_ns - t) > kToleranceNs) return std::nullopt;
  const Eigen::Vector3d e = earth::differenceNed(best->position, reference);
  Judged j{e.head<2>().norm(), best->sigma_h_m, best->valid, std::abs(e.z())};
  takeIntegrity(*best, j);
  return j;
}

/// Protection levels against the true error over the judged epochs (seed 000's integrity
/// claim): an epoch whose solution says AVAILABLE must have its horizontal error within HPL and
/// its vertical error within VPL; one that does not is misleading.
struct ProtectionTally {
  std::size_t epochs{0};
  std::size_t monitored{0};  ///< with levels computed
  std::size_t available{0};
  std::size_t initializing{0};  ///< monitored, the detector's hypotheses not yet formed
  std::size_t misleading_h{0}, misleading_v{0};
  double worst_h_ratio{0.0}, worst_v_ratio{0.0};  ///< largest e / PL while available

  void add(const Judged& j) {
    ++epochs;
    // Monitored: levels computed (0 while not monitored or initializing; an untrustworthy
    // solution is UNAVAILABLE whether monitored or not).
    if (!(j.hpl_m > 0.0 && j.vpl_m > 0.0)) return;
    ++monitored;
    initializing += j.integrity == navbus::INTEGRITY_INITIALIZING ? 1 : 0;
    if (j.integrity != navbus::INTEGRITY_AVAILABLE) return;
    ++available;
    misleading_h += j.horizontal_m > j.hpl_m ? 1 : 0;
    misleading_v += j.vertical_m > j.vpl_m ? 1 : 0;
    worst_h_ratio = std::max(worst_h_ratio, j.horizontal_m / j.hpl_m);
    worst_v_ratio = std::max(worst_v_ratio, j.vertical_m / j.vpl_m);
  }
  double availableShare() const {
    return epochs == 0 ? 0.0 : static_cast<double>(available) / static_cast<double>(epochs);
  }
  std::string line() const {
    if (monitored == 0)
      return fmt::format(
          "protection levels: not monitored in any of the {} judged epochs (the filter has no "
          "integrity block, or no fault manager judged its pseudorange epochs)\n",
          epochs);
    return fmt::format(
        "protection levels: {} judged epochs, monitored {}, available {} ({:.1f} %; "
        "initializing {}, unavailable {}); while available, error beyond HPL {} and beyond VPL "
        "{} (largest e_h / HPL {:.2f}, e_v / VPL {:.2f})\n",
        epochs, monitored, available, 100.0 * availableShare(), initializing,
        monitored - available - initializing, misleading_h, misleading_v, worst_h_ratio,
        worst_v_ratio);
  }
};

struct OutageScore {
  std::size_t epochs{0};
  double end_error_m{0.0};
  double max_error_m{0.0};
  double sum_squares{0.0};
  std::size_t inside_3_sigma{0};
};

/// The scores of one run over every outage, and with GNSS available.
struct Scored {
  std::vector<OutageScore> outages;
  std::size_t scored{0};  ///< outages with an epoch judged
  double end_mean_m{0.0}, end_worst_m{0.0}, max_worst_m{0.0}, rms_m{0.0}, inside{0.0};
  std::size_t epochs{0};
  std::size_t available{0};
  double available_rms_m{0.0};
  double available_inside{0.0};  ///< share of GNSS-available epochs inside 3 sigma_h
  CoverageTally outage_coverage, available_coverage;
  ProtectionTally protection;  ///< every judged epoch, outages and GNSS available
  /// Every judged epoch (errors.csv): run, GPS s of week, outage (0: GNSS available), error
  /// and 1-sigma [m], the reference position [deg].
  fmt::memory_buffer epoch_lines;
};

AntennaPoint antennaOf(const core::SmoothedEpoch& e, const Eigen::Vector3d& lever_b) {
  const auto sd = e.sigma.segment<3>(core::layout::kPos.index);
  return {e.time_ns,
          earth::offsetNed(e.state.position, e.state.q_b_to_n * lever_b),
          e.state.vel_ned_mps,
          std::hypot(sd[0], sd[1]),
          sd[2],
          true};
}

void appendPoint(const AntennaPoint& p, const std::string& tail, fmt::memory_buffer& out) {
  fmt::format_to(fmt::appender(out), "{:.6f},{:.10f},{:.10f},{:.4f},{:.4f},{:.4f},{}\n",
                 1e-9 * static_cast<double>(secondsOfWeekNs(p.time_ns)),
                 p.position.latitude_rad / units::kDeg, p.position.longitude_rad / units::kDeg,
                 p.position.height_m, p.sigma_h_m, p.sigma_v_m, tail);
}

/// How a GNSS-available epoch is judged: a causal filter once it fused the epoch's fix, a
/// smoothed run between its epochs, single point positioning at its own epoch.
enum class Judging { kAfterFusion, kInterpolated, kNearest };

/// One line of errors.csv: the run, the reference epoch's time and position, which outage it
/// falls in (0: GNSS available) and the judged horizontal error and 1-sigma [m].
void appendEpoch(const std::string& run, std::int64_t time_ns, int outage,
                 const earth::Geodetic& reference, const Judged& judged, fmt::memory_buffer& out) {
  fmt::format_to(fmt::appender(out), "{},{:.3f},{},{:.4f},{:.4f},{:.10f},{:.10f}\n", run,
                 1e-9 * static_cast<double>(secondsOfWeekNs(time_ns)), outage, judged.horizontal_m,
                 judged.sigma_h_m, reference.latitude_rad / units::kDeg,
                 reference.longitude_rad / units::kDeg);
}

Scored score(const std::string& run, const std::vector<AntennaPoint>& points,
             const importers::PosLog& reference, const std::vector<Outage>& outages,
             Judging judging) {
  Scored r;
  r.outages.resize(outages.size());
  double available_sum = 0.0;
  for (std::size_t i = 0; i < reference.fixes.size(); ++i) {
    if (reference.quality[i] != kQualityFix) continue;
    const navbus::GnssFix& f = reference.fixes[i];
    const auto t = static_cast<std::int64_t>(f.time_gps_ns());
    const earth::Geodetic truth{f.latitude_rad(), f.longitude_rad(), f.height_m()};
    const int k = outageOf(t, outages);
    if (k < 0) {
      std::optional<Judged> e;
      if (judging == Judging::kAfterFusion) {
        e = judgeAfterFusion(points, t, truth);
      } else if (judging == Judging::kNearest) {
        e = judgeNearest(points, t, truth);
      } else {
        e = judge(points, t, truth);
      }
      if (e) {
        available_sum += e->horizontal_m * e->horizontal_m;
        ++r.available;
        r.available_coverage.add(e->horizontal_m, e->sigma_h_m, e->valid);
        r.protection.add(*e);
        appendEpoch(run, t, 0, truth, *e, r.epoch_lines);
      }
      continue;
    }
    const auto judged = judge(points, t, truth);
    if (!judged) continue;
    appendEpoch(run, t, k + 1, truth, *judged, r.epoch_lines);
    OutageScore& s = r.outages[static_cast<std::size_t>(k)];
    ++s.epochs;
    s.end_error_m = judged->horizontal_m;  // the last one judged is the end
    s.max_error_m = std::max(s.max_error_m, judged->horizontal_m);
    s.sum_squares += judged->horizontal_m * judged->horizontal_m;
    s.inside_3_sigma += judged->horizontal_m <= 3.0 * judged->sigma_h_m ? 1 : 0;
    r.outage_coverage.add(judged->horizontal_m, judged->sigma_h_m, judged->valid);
    r.protection.add(*judged);
  }
  double end_sum = 0.0, squares = 0.0;
  for (const OutageScore& s : r.outages) {
    if (s.epochs == 0) continue;
    ++r.scored;
    end_sum += s.end_error_m;
    r.end_worst_m = std::max(r.end_worst_m, s.end_error_m);
    r.max_worst_m = std::max(r.max_worst_m, s.max_error_m);
    squares += s.sum_squares;
    r.epochs += s.epochs;
  }
  if (r.scored > 0) {
    r.end_mean_m = end_sum / static_cast<double>(r.scored);
    r.rms_m = std::sqrt(squares / static_cast<double>(r.epochs));
    r.inside = r.outage_coverage.insideShare(3);
  }
  if (r.available > 0) {
    r.available_rms_m = std::sqrt(available_sum / static_cast<double>(r.available));
    r.available_inside = r.available_coverage.insideShare(3);
  }
  return r;
}

/// The run's table (printed, and written to `table_file`) and its summary lines.
std::string report(const std::string& title, const Scored& r, Judging judging,
                   const std::vector<Outage>& outages, const std::filesystem::path& table_file,
                   const std::string& outage_file) {
  const std::string available = fmt::format(
      "GNSS available: horizontal RMS against {} fixed epochs{} {:.3f} m, inside its own 3 sigma "
      "{:.1f} %\n",
      r.available, judging == Judging::kAfterFusion ? ", each once fused," : "", r.available_rms_m,
      100.0 * r.available_inside);
  if (outages.empty()) return title + ":\n" + available;
  if (r.scored == 0) throw bus::ConfigError(outage_file + ": no fixed epoch falls in an outage");
  std::ofstream table(table_file);
  table << "outage,start_sow,end_sow,epochs,end_error_m,max_error_m,rms_m,inside_3sigma\n";
  std::string text = title + ":\n";
  text += "outage  start [s of week]  epochs  end error [m]  max error [m]  inside 3 sigma\n";
  for (std::size_t k = 0; k < outages.size(); ++k) {
    const OutageScore& s = r.outages[k];
    if (s.epochs == 0) continue;
    text += fmt::format("{:6}  {:17.3f}  {:6}  {:13.2f}  {:13.2f}  {:8}/{}\n", k + 1,
                        outages[k].start_sow, s.epochs, s.end_error_m, s.max_error_m,
                        s.inside_3_sigma, s.epochs);
    table << fmt::format("{},{:.3f},{:.3f},{},{:.4f},{:.4f},{:.4f},{:.4f}\n", k + 1,
                         outages[k].start_sow, outages[k].end_sow, s.epochs, s.end_error_m,
                         s.max_error_m, std::sqrt(s.sum_squares / static_cast<double>(s.epochs)),
                         static_cast<double>(s.inside_3_sigma) / static_cast<double>(s.epochs));
  }
  if (!table) throw bus::ConfigError("cannot write " + table_file.string());
  text += fmt::format(
      "outage end: mean {:.2f} m, worst {:.2f} m; largest inside an outage {:.2f} m; RMS over {} "
      "outage epochs {:.2f} m; inside its own 3 sigma {:.1f} %\n",
      r.end_mean_m, r.end_worst_m, r.max_worst_m, r.epochs, r.rms_m, 100.0 * r.inside);
  return text + available;
}

std::string scoreLine(const std::string& run, const Scored& r) {
  const ProtectionTally& p = r.protection;
  return fmt::format("{},{},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{},{:.4f},{:.4f},{},{},{},{},{}\n",
                     run, r.scored, r.end_mean_m, r.end_worst_m, r.max_worst_m, r.rms_m, r.inside,
                     r.available, r.available_rms_m, r.available_inside, p.epochs, p.monitored,
                     p.available, p.misleading_h, p.misleading_v);
}

/// The honesty table (printed) and coverage.csv: the causal run and, when given, the smoothed
/// one, over the outage epochs and the GNSS-available ones; the causal run's flagged share over
/// every solution it published.
std::string honestyReport(const Scored& causal, const Scored* smoothed,
                          const std::vector<AntennaPoint>& points, bool outages,
                          const std::filesystem::path& csv_file) {
  std::ofstream csv(csv_file);
  csv << kCoverageCsvHeader;
  std::string text =
      "honesty: horizontal error e against the solution's own sigma_h = sqrt(sN^2 + sE^2)\n" +
      coverageHeader();
  auto row = [&](const std::string& run, const std::string& group, const CoverageTally& t,
                 bool flags) {
    if (t.epochs() == 0) return;
    text += coverageRow(run + ", " + group, t, flags);
    csv << coverageCsvLine(run, group, t, flags);
  };
  if (outages) row("causal", "outages", causal.outage_coverage, true);
  row("causal", "GNSS available", causal.available_coverage, true);
  if (smoothed != nullptr) {
    if (outages) row("smoothed", "outages", smoothed->outage_coverage, false);
    row("smoothed", "GNSS available", smoothed->available_coverage, false);
  }
  text += coverageFooter();
  const auto flagged = static_cast<std::size_t>(
      std::count_if(points.begin(), points.end(), [](const AntennaPoint& p) { return !p.valid; }));
  text += fmt::format(
      "solutions published with covariance_valid false: {} of {} ({:.1f} %)\n", flagged,
      points.size(),
      points.empty() ? 0.0
                     : 100.0 * static_cast<double>(flagged) / static_cast<double>(points.size()));
  if (!csv) throw bus::ConfigError("cannot write " + csv_file.string());
  return text;
}

/// With an injected IMU step: when the filter first flagged its solution after the onset, and
/// what it published unflagged until then, judged at the fixed epochs as the scores judge them.
struct StepScore {
  std::int64_t onset_ns{0};
  std::optional<double> first_flag_s;  ///< after the onset; nullopt: never flagged
  std::size_t judged{0};               ///< fixed epochs judged unflagged before the flag
  std::size_t outside{0};              ///< ... of them outside 3 sigma_h
  double largest_m{0.0}, largest_ratio{0.0};
  std::size_t solutions{0}, flagged{0};  ///< from the onset on
};

StepScore scoreStep(const std::vector<AntennaPoint>& points, const importers::PosLog& reference,
                    const std::vector<Outage>& outages, std::int64_t onset_ns) {
  StepScore r;
  r.onset_ns = onset_ns;
  const auto after_onset =
      std::lower_bound(points.begin(), points.end(), onset_ns,
                       [](const AntennaPoint& p, std::int64_t v) { return p.time_ns < v; });
  const auto first_flag =
      std::find_if(after_onset, points.end(), [](const AntennaPoint& p) { return !p.valid; });
  std::int64_t flag_ns = std::numeric_limits<std::int64_t>::max();
  if (first_flag != points.end()) {
    flag_ns = first_flag->time_ns;
    r.first_flag_s = 1e-9 * static_cast<double>(flag_ns - onset_ns);
  }
  r.solutions = static_cast<std::size_t>(points.end() - after_onset);
  r.flagged = static_cast<std::size_t>(
      std::count_if(after_onset, points.end(), [](const AntennaPoint& p) { return !p.valid; }));
  for (std::size_t i = 0; i < reference.fixes.size(); ++i) {
    const auto t = static_cast<std::int64_t>(reference.fixes[i].time_gps_ns());
    if (reference.quality[i] != kQualityFix || t < onset_ns || t >= flag_ns) continue;
    const navbus::GnssFix& f = reference.fixes[i];
    const earth::Geodetic truth{f.latitude_rad(), f.longitude_rad(), f.height_m()};
    const auto e =
        outageOf(t, outages) >= 0 ? judge(points, t, truth) : judgeAfterFusion(points, t, truth);
    if (!e || !e->valid) continue;
    ++r.judged;
    r.outside += e->horizontal_m > 3.0 * e->sigma_h_m ? 1 : 0;
    r.largest_m = std::max(r.largest_m, e->horizontal_m);
    r.largest_ratio = std::max(r.largest_ratio, e->horizontal_m / e->sigma_h_m);
  }
  return r;
}

/// The step's score, printed and as step.csv.
std::string stepReport(const StepScore& r, const std::filesystem::path& csv_file) {
  const double onset_sow = 1e-9 * static_cast<double>(secondsOfWeekNs(r.onset_ns));
  std::ofstream csv(csv_file);
  csv << "onset_sow,first_flag_after_s,judged_unflagged,outside_3sigma,largest_error_m,"
         "largest_ratio,solutions,flagged\n"
      << fmt::format("{:.3f},{},{},{},{:.4f},{:.3f},{},{}\n", onset_sow,
                     r.first_flag_s ? fmt::format("{:.3f}", *r.first_flag_s) : "", r.judged,
                     r.outside, r.largest_m, r.largest_ratio, r.solutions, r.flagged);
  if (!csv) throw bus::ConfigError("cannot write " + csv_file.string());
  std::string text =
      r.first_flag_s
          ? fmt::format(
                "injected IMU step from {:.3f} s of week: first flagged {:.2f} s after the onset",
                onset_sow, *r.first_flag_s)
          : fmt::format("injected IMU step from {:.3f} s of week: never flagged after the onset",
                        onset_sow);
  return text + fmt::format(
                    "; before that, {} fixed epochs judged unflagged, {} outside 3 sigma_h "
                    "(largest error {:.3f} m, largest e / sigma_h {:.2f}); {} of the {} "
                    "solutions from the onset on flagged\n",
                    r.judged, r.outside, r.largest_m, r.largest_ratio, r.flagged, r.solutions);
}

}  // namespace

std::vector<Outage> outageSchedule(const OutageSchedule& s, double last_sow) {
  if (!(s.length_s > 0.0 && s.period_s > s.length_s))
    throw bus::ConfigError(fmt::format(
        "--outage-schedule: length {} s and period {} s must be positive with the length shorter "
        "than the period",
        s.length_s, s.period_s));
  if (!(s.first_start_sow >= 0.0 && s.first_start_sow < last_sow))
    throw bus::ConfigError(fmt::format(
        "--outage-schedule: first start {} s of week is not within the log (last epoch {:.3f})",
        s.first_start_sow, last_sow));
  std::vector<Outage> out;
  for (double start = s.first_start_sow; start + s.length_s <= last_sow; start += s.period_s)
    out.push_back({start, start + s.length_s});
  if (out.empty())
    throw bus::ConfigError(fmt::format(
        "--outage-schedule: no {} s outage from {} s of week ends before the log's last epoch "
        "({:.3f})",
        s.length_s, s.first_start_sow, last_sow));
  return out;
}

std::vector<Outage> readOutages(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw bus::ConfigError(file.string() + ": cannot be read");
  std::vector<Outage> out;
  std::string text;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    text = text.substr(0, text.find('#'));
    std::istringstream fields(text);
    Outage o;
    std::string rest;
    if (!(fields >> o.start_sow)) {
      if (text.find_first_not_of(" \t\r") == std::string::npos) continue;  // blank, comment
      throw bus::ConfigError(
          fmt::format("{} line {}: '{}' is not `START END` (GPS seconds of "
                      "week)",
                      file.string(), line, text));
    }
    if (!(fields >> o.end_sow) || (fields >> rest))
      throw bus::ConfigError(
          fmt::format("{} line {}: '{}' is not `START END`", file.string(), line, text));
    if (!(o.start_sow >= 0.0 && o.end_sow > o.start_sow && o.end_sow <= core::gps::kSecondsPerWeek))
      throw bus::ConfigError(
          fmt::format("{} line {}: outage {} .. {} is not within a week and "
                      "of positive length",
                      file.string(), line, o.start_sow, o.end_sow));
    out.push_back(o);
  }
  if (out.empty()) throw bus::ConfigError(file.string() + ": no outage");
  return out;
}

int runRealCarBenchmark(const RealCarOptions& o) {
  importers::DatasetDescription dataset = importers::readDatasetDescription(o.dataset);
  if (!dataset.imu || !dataset.gnss_solutions)
    throw bus::ConfigError(o.dataset + ": the benchmark needs imu and gnss_solutions");
  dataset.imu->step = o.imu_step;
  const std::filesystem::path out_dir(o.out_dir);
  const importers::ImportReport imported = importers::importDataset(dataset, out_dir / "recording");
  // The reference: the fixed epochs of the same file, read as the import read them.
  const importers::PosLog reference = importers::readPosFile(*dataset.gnss_solutions);
  std::vector<Outage> outages;
  if (!o.outages.empty()) {
    outages = readOutages(o.outages);
  } else if (o.schedule) {
    if (reference.fixes.empty()) throw bus::ConfigError(o.dataset + ": no GNSS solution");
    outages = outageSchedule(
        *o.schedule, 1e-9 * static_cast<double>(secondsOfWeekNs(
                                static_cast<std::int64_t>(reference.fixes.back().time_gps_ns()))));
  }
  const std::string outage_source = o.outages.empty() ? "--outage-schedule" : o.outages;

  RecordingSetup setup;
  setup.dir = out_dir / "recording";
  setup.filter = bus::parseFile(o.filter, nav_filter::parseFilterConfig);
  setup.withhold = [&](const navbus::GnssFix& f) {
    return outageOf(static_cast<std::int64_t>(f.time_gps_ns()), outages) >= 0;
  };
  setup.smooth = o.smooth;
  if (!o.fault_manager.empty())
    setup.fault_manager = bus::parseFile(o.fault_manager, fault_manager::parseFaultManagerConfig);
  const Eigen::Vector3d lever_b = setup.filter.engine.antenna_lever_arm_b_m;
  std::vector<AntennaPoint> points;
  std::ofstream sol(out_dir / "solution.csv");
  if (!sol) throw bus::ConfigError("cannot write into " + o.out_dir);
  sol << "gpst_s,lat_deg,lon_deg,height_m,sigma_h_m,sigma_v_m,mode,covariance_valid\n";
  fmt::memory_buffer buffer;
  const RecordingResult run = runRecording(setup, [&](const navbus::NavigationSolution& s) {
    if (s.mode() == navbus::MODE_INITIALIZING || s.mode() == navbus::MODE_INERTIAL_LOST) return;
    const AntennaPoint p = antennaOf(s, lever_b);
    points.push_back(p);
    appendPoint(p, fmt::format("{},{}", static_cast<int>(s.mode()), s.covariance_valid() ? 1 : 0),
                buffer);
  });
  sol.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));

  std::string text = fmt::format("{}{}\n{} fixes withheld in {} outages\n", imported.text,
                                 run.summary, run.fixes_withheld, outages.size());
  std::ofstream scores(out_dir / "scores.csv");
  scores << "run,outages_scored,end_mean_m,end_worst_m,max_worst_m,rms_m,inside_3sigma,"
            "available_epochs,available_rms_m,available_inside_3sigma,pl_epochs,pl_monitored,"
            "pl_available,pl_misleading_h,pl_misleading_v\n";
  const Scored causal = score("filter", points, reference, outages, Judging::kAfterFusion);
  text += report("the filter (causal)", causal, Judging::kAfterFusion, outages,
                 out_dir / "outages.csv", outage_source);
  text += causal.protection.line();
  scores << scoreLine("filter", causal);
  std::ofstream epochs(out_dir / "errors.csv");
  epochs << "run,gpst_s,outage,error_h_m,sigma_h_m,ref_lat_deg,ref_lon_deg\n";
  epochs.write(causal.epoch_lines.data(), static_cast<std::streamsize>(causal.epoch_lines.size()));
  std::string written = outages.empty() ? "solution.csv, scores.csv, errors.csv"
                                        : "solution.csv, outages.csv, scores.csv, errors.csv";
  std::optional<Scored> backward;
  if (o.smooth) {
    std::vector<AntennaPoint> smoothed;
    smoothed.reserve(run.smoothed.size());
    fmt::memory_buffer lines;
    for (const core::SmoothedEpoch& e : run.smoothed) {
      smoothed.push_back(antennaOf(e, lever_b));
      appendPoint(smoothed.back(), e.smoothed ? "1" : "0", lines);
    }
    std::ofstream file(out_dir / "smoothed.csv");
    file << "gpst_s,lat_deg,lon_deg,height_m,sigma_h_m,sigma_v_m,smoothed\n";
    file.write(lines.data(), static_cast<std::streamsize>(lines.size()));
    backward = score("smoothed", smoothed, reference, outages, Judging::kInterpolated);
    text += run.smoother_summary + "\n";
    text += report("smoothed (--smooth)", *backward, Judging::kInterpolated, outages,
                   out_dir / "smoothed_outages.csv", outage_source);
    scores << scoreLine("smoothed", *backward);
    epochs.write(backward->epoch_lines.data(),
                 static_cast<std::streamsize>(backward->epoch_lines.size()));
    written += outages.empty() ? ", smoothed.csv" : ", smoothed.csv, smoothed_outages.csv";
  }
  text += honestyReport(causal, backward ? &*backward : nullptr, points, !outages.empty(),
                        out_dir / "coverage.csv");
  if (imported.imu_step_onset_gps_ns >= 0) {
    text += stepReport(scoreStep(points, reference, outages, imported.imu_step_onset_gps_ns),
                       out_dir / "step.csv");
    written += ", step.csv";
  }
  written += ", coverage.csv";
  writeFixInnovationsCsv(out_dir / "innovations.csv", run.fix_innovations);
  written += ", innovations.csv";
  if (dataset.gnss_observations) {
    // The receiver's own pseudoranges alone, epoch by epoch: what the filter adds to them.
    const importers::ObservationLog log =
        importers::readRinexObservations(*dataset.gnss_observations);
    std::vector<AntennaPoint> spp;
    for (const importers::SinglePointEpoch& e : log.single_point)
      spp.push_back({e.time_ns, core::earth::ecefToGeodetic(e.pos_ecef_m), Eigen::Vector3d::Zero(),
                     e.sigma_h_m, e.sigma_v_m, true});
    const Scored single = score("spp", spp, reference, {}, Judging::kNearest);
    text += report("single point positioning of the same pseudoranges (" +
                       std::to_string(spp.size()) + " epochs solved)",
                   single, Judging::kNearest, {}, {}, outage_source);
    scores << scoreLine("spp", single);
    epochs.write(single.epoch_lines.data(),
                 static_cast<std::streamsize>(single.epoch_lines.size()));
  }
  if (!sol || !scores || !epochs) throw bus::ConfigError("cannot write into " + o.out_dir);
  text += fmt::format("written into {}: {}\n", o.out_dir, written);
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace navbus::evaluation
