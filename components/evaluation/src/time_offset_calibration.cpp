#include "navbus/evaluation/time_offset_calibration.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>

#include <fmt/format.h>

#include "navbus/bus/config.hpp"

namespace navbus::evaluation {

namespace {

/// Which rows a search minimizes, and how a candidate changes the configuration.
struct SearchKind {
  bool position_rows;
  std::function<double(nav_filter::FilterConfig&, double)> apply;  ///< returns the offset set
};

OffsetTrial runWith(const RecordingSetup& base, const SearchKind& kind, double candidate_s) {
  RecordingSetup setup = base;
  setup.smooth = false;
  const double offset_s = kind.apply(setup.filter, candidate_s);
  const RecordingResult r = runRecording(setup);
  const core::InnovationStatistics& mine =
      kind.position_rows ? r.fix_position_nis : r.fix_velocity_nis;
  const core::InnovationStatistics& other =
      kind.position_rows ? r.fix_velocity_nis : r.fix_position_nis;
  if (mine.rows == 0)
    throw bus::ConfigError(fmt::format(
        "time offset {:.3f} s: the filter fused no GNSS fix, nothing to calibrate on", offset_s));
  return {offset_s,
          mine.mean(),
          other.mean(),
          mine.rows,
          r.consistency.epochs_tested,
          r.consistency.epochs_inconsistent};
}

/// The minimum of the parabola through (x - h, f0), (x, f1), (x + h, f2); x when it is flat.
double parabolaMinimum(double x, double h, double f0, double f1, double f2) {
  const double curvature = f0 - 2.0 * f1 + f2;
  if (!(curvature > 0.0)) return x;
  return x + 0.5 * h * (f0 - f2) / curvature;
}

OffsetSearch search(const RecordingSetup& base, const Grid& g, const SearchKind& kind) {
  if (!(g.step_s > 0.0) || !(g.to_s >= g.from_s) || (g.to_s - g.from_s) / g.step_s > 1000.0)
    throw bus::ConfigError(fmt::format(
        "time-offset grid from {} to {} by {}: needs from <= to and a positive step, at most "
        "1000 candidates",
        g.from_s, g.to_s, g.step_s));
  OffsetSearch s;
  const auto n = static_cast<int>(std::floor((g.to_s - g.from_s) / g.step_s + 1e-9)) + 1;
  for (int i = 0; i < n; ++i) {
    s.trials.push_back(runWith(base, kind, g.from_s + i * g.step_s));
    if (s.trials.back().mean_nis < s.trials[s.best].mean_nis) s.best = s.trials.size() - 1;
  }
  const OffsetTrial& b = s.trials[s.best];
  s.at_edge = s.best == 0 || s.best + 1 == s.trials.size();
  s.refined_s = s.at_edge ? b.offset_s
                          : parabolaMinimum(b.offset_s, g.step_s, s.trials[s.best - 1].mean_nis,
                                            b.mean_nis, s.trials[s.best + 1].mean_nis);
  return s;
}

std::int64_t nanoseconds(double s) {
  return std::llround(s * 1e9);
}

/// One search's grid as text and CSV lines; `upper_edge_is_bound`: a minimum at the grid's last
/// offset is a real answer (the velocity's lag is at most 0), not a grid to widen.
std::string table(const std::string& key, const char* rows, const char* other,
                  const OffsetSearch& s, const std::string& stage, bool upper_edge_is_bound,
                  std::ofstream& csv) {
  std::string text = fmt::format(
      "{:>40}  mean NIS: {} rows ({})  windows failing the consistency test\n", key, rows, other);
  for (const OffsetTrial& t : s.trials) {
    const double failing = t.epochs_tested > 0
                               ? 100.0 * static_cast<double>(t.epochs_inconsistent) /
                                     static_cast<double>(t.epochs_tested)
                               : 0.0;
    text += fmt::format("{:40.3f}  {:10.3f} ({:.3f})  {:5.1f} %{}\n", t.offset_s, t.mean_nis,
                        t.other_nis, failing, &t == &s.trials[s.best] ? "  <- smallest" : "");
    csv << fmt::format("{},{:.4f},{:.5f},{:.5f},{},{},{}\n", stage, t.offset_s, t.mean_nis,
                       t.other_nis, t.rows, t.epochs_tested, t.epochs_inconsistent);
  }
  if (s.at_edge && upper_edge_is_bound && s.best + 1 == s.trials.size()) {
    text += fmt::format("smallest at {:.3f} s, the grid's upper bound: no lag\n",
                        s.trials[s.best].offset_s);
  } else if (s.at_edge) {
    text += fmt::format("the smallest mean NIS is at the grid's edge ({:.3f} s): widen the grid\n",
                        s.trials[s.best].offset_s);
  } else {
    text += fmt::format("smallest at {:.3f} s; the parabola through its neighbours: {:.3f} s\n",
                        s.trials[s.best].offset_s, s.refined_s);
  }
  return text;
}

}  // namespace

OffsetSearch searchImuTimeOffset(const RecordingSetup& base, const Grid& grid) {
  const std::int64_t configured_ns = base.filter.imu.time_offset_ns;
  return search(base, grid,
                {true, [configured_ns](nav_filter::FilterConfig& f, double candidate_s) {
                   f.imu.time_offset_ns = configured_ns + nanoseconds(candidate_s);
                   return 1e-9 * static_cast<double>(f.imu.time_offset_ns);
                 }});
}

OffsetSearch searchVelocityTimeOffset(const RecordingSetup& base, const Grid& grid) {
  if (!base.filter.gnss_fix)
    throw bus::ConfigError("the filter configuration has no inputs.gnss_fix to calibrate");
  if (grid.to_s > 0.0)
    throw bus::ConfigError(fmt::format(
        "velocity time-offset grid up to {} s: a velocity offset is 0 or negative (a lag)",
        grid.to_s));
  return search(base, grid, {false, [](nav_filter::FilterConfig& f, double candidate_s) {
                               f.gnss_fix->velocity_time_offset_ns = nanoseconds(candidate_s);
                               return candidate_s;
                             }});
}

int runTimeOffsetCommand(const TimeOffsetOptions& o) {
  const std::filesystem::path out_dir(o.out_dir);
  ImportedRun imported = importForRun(o.dataset, o.filter, out_dir);
  RecordingSetup& setup = imported.setup;

  std::ofstream csv(out_dir / "time_offset.csv");
  csv << "round_stage,offset_s,mean_nis,other_rows_mean_nis,rows,epochs_tested,epochs_"
         "inconsistent\n";
  std::string text = imported.import_text;
  // Coordinate descent: each offset's misfit leaks into the other's rows a little, so the two
  // searches alternate (the IMU grid is always about the configured offset).
  const std::int64_t configured_imu_ns = setup.filter.imu.time_offset_ns;
  OffsetSearch imu, velocity;
  for (int round = 1; round <= o.rounds; ++round) {
    setup.filter.imu.time_offset_ns = configured_imu_ns;
    text += fmt::format(
        "round {}, 1. the IMU's offset, from the fixes' position rows (the fix "
        "velocity at {:.3f} s)\n",
        round,
        1e-9 * static_cast<double>(
                   setup.filter.gnss_fix ? setup.filter.gnss_fix->velocity_time_offset_ns : 0));
    imu = searchImuTimeOffset(setup, o.imu);
    text += table("inputs.imu.time_offset_s", "position", "velocity", imu,
                  fmt::format("{} imu", round), false, csv);
    if (imu.at_edge) {
      std::fputs(text.c_str(), stdout);
      return 1;
    }
    setup.filter.imu.time_offset_ns = nanoseconds(imu.refined_s);
    text += fmt::format(
        "round {}, 2. with the IMU at {:.3f} s, the fix velocity's offset, from its rows\n", round,
        imu.refined_s);
    velocity = searchVelocityTimeOffset(setup, o.velocity);
    text += table("inputs.gnss_fix.velocity_time_offset_s", "velocity", "position", velocity,
                  fmt::format("{} velocity", round), true, csv);
    if (velocity.at_edge && velocity.best == 0) {  // below the grid's lowest lag: widen it
      std::fputs(text.c_str(), stdout);
      return 1;
    }
    setup.filter.gnss_fix->velocity_time_offset_ns = nanoseconds(velocity.refined_s);
  }
  if (!csv) throw bus::ConfigError("cannot write into " + o.out_dir);
  text += fmt::format(
      "inputs:\n  imu: {{time_offset_s: {:.3f}}}\n  gnss_fix: {{velocity_time_offset_s: {:.3f}}}\n"
      "written into {}: time_offset.csv, the recording\n",
      imu.refined_s, velocity.refined_s, o.out_dir);
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace navbus::evaluation
