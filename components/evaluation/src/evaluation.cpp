#include "navbus/evaluation/evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

#include <spdlog/spdlog.h>
#include <boost/math/distributions/chi_squared.hpp>

#include "navbus/bus/app.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/evaluation/fault_evaluation.hpp"
#include "navbus/evaluation/integrity_evaluation.hpp"
#include "navbus/evaluation/offline_runner.hpp"
#include "navbus/evaluation/parallel_runs.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/records/formatters.hpp"

namespace navbus::evaluation {

namespace {

constexpr double kArcsecPerRad = 180.0 / M_PI * 3600.0;

/// The protection levels assume the detector the fault manager runs: refuses a filter whose
/// integrity.detector differs from the fault manager's glr block, naming the key and both values.
void checkIntegrityDetector(const nav_filter::FilterConfig& filter,
                            const fault_manager::FaultManagerConfig& faults,
                            const std::string& filter_path, const std::string& faults_path) {
  const core::IntegrityConfig& i = filter.engine.integrity;
  if (!i.enabled) return;
  const core::GlrConfig& a = i.detector;
  const core::GlrConfig& b = faults.glr.glr;
  const auto differ = [&](const char* key, double x, double y) {
    if (x == y) return;
    throw bus::ConfigError("configuration integrity.detector." + std::string(key) + " of " +
                           filter_path + " is " + records::formatNumber(x) + " but glr." + key +
                           " of " + faults_path + " is " + records::formatNumber(y) +
                           ": the protection levels assume the fault manager's detector");
  };
  differ("window_epochs", a.window, b.window);
  differ("threshold", a.threshold, b.threshold);
  differ("hypotheses.imu_steps", a.imu_steps, b.imu_steps);
  differ("hypotheses.range_steps", a.range_steps, b.range_steps);
  differ("hypotheses.range_ramps", a.range_ramps, b.range_ramps);
  differ("hypotheses.rate_steps", a.rate_steps, b.rate_steps);
  // Only a filter fusing two receivers gives the GLR rows of several receivers.
  if (filter.second_gnss_receiver_id)
    differ("hypotheses.per_receiver_satellites", a.per_receiver_satellites,
           b.per_receiver_satellites);
}

/// `filter_yaml` is the filter file's content (the Monte Carlo overrides some keys);
/// `filter_path` names it in errors.
OfflineSetup loadSetup(const std::string& scenario, const YAML::Node& filter_yaml,
                       const std::string& filter_path, std::uint64_t seed, double duration_s,
                       const std::string& fault_manager = "") {
  OfflineSetup s;
  if (!fault_manager.empty())
    s.fault_manager = bus::parseFile(fault_manager, fault_manager::parseFaultManagerConfig);
  s.sim = bus::parseFile(scenario, sensor_sim::parseSimConfig);
  if (seed != 0) s.sim.scenario.seed = seed;
  try {
    s.filter = nav_filter::parseFilterConfig(filter_yaml);
  } catch (const bus::ConfigError& e) {
    bus::rethrowNamingFile(filter_path, e);
  }
  if (s.fault_manager)
    checkIntegrityDetector(s.filter, *s.fault_manager, filter_path, fault_manager);
  s.duration_s = duration_s > 0.0 ? duration_s : s.sim.duration_s;
  if (!(s.duration_s > 0.0)) {
    throw bus::ConfigError("scenario " + scenario +
                           " has no timing.duration_s; give --duration (seconds of data)");
  }
  return s;
}

std::string fmt(double v) {
  return records::formatNumber(v);
}

/// A filter YAML; with `align`, without its initial_state (the filter aligns from its inputs).
YAML::Node filterYaml(const std::string& path, bool align) {
  YAML::Node y = YAML::Clone(bus::loadYamlFile(path));
  if (align) y.remove("initial_state");
  return y;
}

void writeTruthHeader(std::ofstream& f) {
  f << "time_gps_ns,latitude_rad,longitude_rad,height_m,vel_ned_mps[0],vel_ned_mps[1],"
       "vel_ned_mps[2],roll_rad,pitch_rad,yaw_rad\n";
}

void writeErrorHeader(std::ofstream& f) {
  f << "time_gps_ns,mode,pos_err_ned_m[0],pos_err_ned_m[1],pos_err_ned_m[2],vel_err_ned_mps[0],"
       "vel_err_ned_mps[1],vel_err_ned_mps[2],att_err_ned_rad[0],att_err_ned_rad[1],"
       "att_err_ned_rad[2],pos_sigma_ned_m[0],pos_sigma_ned_m[1],pos_sigma_ned_m[2],"
       "vel_sigma_ned_mps[0],vel_sigma_ned_mps[1],vel_sigma_ned_mps[2],att_sigma_ned_rad[0],"
       "att_sigma_ned_rad[1],att_sigma_ned_rad[2],nees9,accel_bias_err_b_mps2[0],"
       "accel_bias_err_b_mps2[1],accel_bias_err_b_mps2[2],gyro_bias_err_b_radps[0],"
       "gyro_bias_err_b_radps[1],gyro_bias_err_b_radps[2],star_tracker_bias_err_b_rad[0],"
       "star_tracker_bias_err_b_rad[1],star_tracker_bias_err_b_rad[2],nees_pos,nees_vel,nees_att,"
       "nees_accel_bias,nees_gyro_bias,nees_star_tracker_bias\n";
}

/// Statistics of a set of runs of one configuration.
struct Stats {
  double sum_pos2{0}, sum_vel2{0}, sum_att2{0};
  double max_pos{0}, max_vel{0}, max_att{0};
  std::size_t n{0};
  // NEES: per epoch index, summed over runs.
  std::vector<double> nees_sum;
  using Blocks = Eigen::Matrix<double, kNeesBlocks, 1>;
  std::vector<Blocks> nees_blocks_sum;  ///< as EpochError::nees_blocks
  std::vector<int> nees_runs;
  std::vector<double> nees_time_s;  ///< of epoch index k, from the start (the first run's)
  std::vector<double> recovery_s;   ///< per run and instant; NaN when not converged
};

void accumulate(Stats& st, const OfflineResult& r, std::int64_t from_ns, const MonteCarloOptions& o,
                std::int64_t start_ns) {
  std::size_t k = 0;
  for (const EpochError& e : r.errors) {
    if (e.time_ns < from_ns) continue;
    const double p = e.pos_ned_m.norm(), v = e.vel_ned_mps.norm(), a = e.att_ned_rad.norm();
    st.sum_pos2 += p * p;
    st.sum_vel2 += v * v;
    st.sum_att2 += a * a;
    st.max_pos = std::max(st.max_pos, p);
    st.max_vel = std::max(st.max_vel, v);
    st.max_att = std::max(st.max_att, a);
    ++st.n;
    if (st.nees_sum.size() <= k) {
      st.nees_sum.resize(k + 1, 0.0);
      st.nees_blocks_sum.resize(k + 1, Stats::Blocks::Zero());
      st.nees_runs.resize(k + 1, 0);
      st.nees_time_s.push_back(1e-9 * static_cast<double>(e.time_ns - start_ns));
    }
    // A solution scored from its message (a lane's engine had moved on) has no covariance.
    if (std::isfinite(e.nees9)) {
      st.nees_sum[k] += e.nees9;
      st.nees_blocks_sum[k] += e.nees_blocks;
      ++st.nees_runs[k];
    }
    ++k;
  }
  for (double t_s : o.recovery_after_s) {
    const std::int64_t t0 = start_ns + static_cast<std::int64_t>(std::llround(t_s * 1e9));
    st.recovery_s.push_back(
        convergenceTime(r.errors, t0, o.recovery_threshold_m, o.recovery_window_s));
  }
}

double median(std::vector<double> v);

/// What one run's alignment started from, against the truth.
struct AlignmentOutcome {
  bool aligned{false};
  core::AlignedStart start;
  EpochError error;  ///< start minus truth, with the start's own sigmas
  double time_s{0};  ///< from the scenario's start to the aligned start
};

const char* attitudeSourceName(core::AttitudeSource s) {
  switch (s) {
    case core::AttitudeSource::kStarTracker:
      return "star tracker";
    case core::AttitudeSource::kGyrocompass:
      return "gyrocompassing";
    case core::AttitudeSource::kGnssCourse:
      return "GNSS course";
    case core::AttitudeSource::kNone:
      break;
  }
  return "none";
}

/// What gyrocompassing would reach with this IMU here (the aligner's formula), or why it
/// does not apply (beyond 0.5 rad its small-angle formula has no meaning).
std::string gyrocompassingLimitText(double limit_rad) {
  if (!(limit_rad > 0.0)) return "gyrocompassing limit not computed (no static window)";
  if (limit_rad > 0.5) {
    return fmt::format(
        "gyrocompassing not possible with this gyro grade (its formula gives {:.0f} "
        "mrad)",
        1e3 * limit_rad);
  }
  return fmt::format("gyrocompassing limit with this IMU here {:.2f} mrad", 1e3 * limit_rad);
}

/// The alignment's starts of one configuration: how long they took, where the attitude came
/// from, and whether the start's error is inside 3 of its own sigmas (tilt N, tilt E, heading).
void printAlignment(const std::string& label, const std::vector<AlignmentOutcome>& runs) {
  std::vector<double> times, heading_sigma, limit;
  std::map<std::string, int> sources;
  double heading2 = 0, tilt2 = 0;
  int aligned = 0, inside = 0;
  for (const AlignmentOutcome& a : runs) {
    if (!a.aligned) continue;
    ++aligned;
    times.push_back(a.time_s);
    ++sources[attitudeSourceName(a.start.attitude_source)];
    const Eigen::Vector3d& e = a.error.att_ned_rad;
    const Eigen::Vector3d& s = a.start.att_sigma_ned_rad;
    heading2 += e.z() * e.z();
    tilt2 += 0.5 * e.head<2>().squaredNorm();
    heading_sigma.push_back(s.z());
    limit.push_back(a.start.gyrocompass_heading_sigma_rad);
    inside += (e.array().abs() <= 3.0 * s.array()).all() ? 1 : 0;
  }
  std::string from;
  for (const auto& [name, n] : sources)
    from += (from.empty() ? "" : ", ") + name + " " + std::to_string(n);
  const double n = std::max(aligned, 1);
  std::printf(
      "\nalignment, %s: %d of %zu runs aligned (attitude from %s); time to align median %.1f s,"
      " max %.1f s\n  attitude error of the start: tilt RMS %.3f mrad, heading RMS %.2f mrad "
      "against a reported heading sigma of %.2f mrad (median); %s (median);\n  every axis within "
      "3 of its own sigmas in %d of %d runs\n",
      label.c_str(), aligned, runs.size(), from.empty() ? "-" : from.c_str(), median(times),
      times.empty() ? 0.0 : *std::max_element(times.begin(), times.end()),
      1e3 * std::sqrt(tilt2 / n), 1e3 * std::sqrt(heading2 / n), 1e3 * median(heading_sigma),
      gyrocompassingLimitText(median(limit)).c_str(), inside, aligned);
}

/// Median with runs that never converged counted as infinitely slow.
double median(std::vector<double> v) {
  for (double& x : v) {
    if (std::isnan(x)) x = std::numeric_limits<double>::infinity();
  }
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

/// Average NEES per state block (3 degrees of freedom each) over the epochs every run reached.
template <class Rows>
void printBlockNees(const Rows& rows, int runs) {
  const double lo = chiSquareQuantile(0.025, 3.0 * runs) / runs;
  const double hi = chiSquareQuantile(0.975, 3.0 * runs) / runs;
  std::printf("\naverage NEES per block (3 degrees of freedom each, 95%% band [%.2f, %.2f])\n", lo,
              hi);
  std::printf("%-34s %10s %10s %10s %10s %10s %10s\n", "configuration", "position", "velocity",
              "attitude", "accel bias", "gyro bias", "star bias");
  for (const auto& r : rows) {
    Stats::Blocks mean = Stats::Blocks::Zero();
    int epochs = 0;
    for (std::size_t k = 0; k < r.st.nees_blocks_sum.size(); ++k) {
      if (r.st.nees_runs[k] != runs) continue;
      mean += r.st.nees_blocks_sum[k] / runs;
      ++epochs;
    }
    mean /= std::max(epochs, 1);
    std::printf("%-34s", r.label.c_str());
    // "-": a block the filter does not estimate.
    for (int b = 0; b < kNeesBlocks; ++b) {
      if (std::isnan(mean[b]))
        std::printf(" %10s", "-");
      else
        std::printf(" %10.2f", mean[b]);
    }
    std::printf("\n");
  }
}

/// Average NEES over the runs at every epoch all of them reached, with the 95 % band.
void writeNeesCsv(std::ofstream& f, const std::string& label, const Stats& s, int runs, double lo,
                  double hi) {
  for (std::size_t k = 0; k < s.nees_sum.size(); ++k) {
    if (s.nees_runs[k] != runs) continue;
    f << records::csvQuote(label) << "," << fmt(s.nees_time_s[k]) << ","
      << fmt(s.nees_sum[k] / runs) << "," << fmt(lo) << "," << fmt(hi) << "," << runs << "\n";
  }
}

void writeFaultRunsCsv(std::ofstream& f, const std::string& label,
                       const std::optional<sim::Fault>& fault,
                       const std::vector<FaultRunOutcome>& runs) {
  const double fault_s = fault ? fault->start_s : std::nan("");
  for (const FaultRunOutcome& r : runs) {
    f << records::csvQuote(label) << "," << r.seed << "," << fmt(fault_s) << ","
      << (r.detected ? 1 : 0) << "," << (r.detected ? fmt(r.detection_s) : "") << ","
      << (r.detected && fault ? fmt(r.detection_s - fault_s) : "") << ","
      << (r.detected ? fmt(r.onset_s) : "") << "," << r.class_correct << "," << r.source_correct
      << "," << r.ambiguous << "," << r.false_alarms << ","
      << (std::isnan(r.recovery_s) ? "" : fmt(r.recovery_s)) << "," << records::csvQuote(r.decided)
      << "," << r.decisions << "\n";
  }
}

}  // namespace

double convergenceTime(const std::vector<EpochError>& errors, std::int64_t t0_ns,
                       double threshold_m, double window_s) {
  // The first epoch after t0 from which the horizontal position error stays below the
  // threshold for the whole window.
  const auto window = static_cast<std::int64_t>(std::llround(window_s * 1e9));
  for (std::size_t i = 0; i < errors.size(); ++i) {
    const EpochError& e = errors[i];
    if (e.time_ns < t0_ns || e.time_ns > t0_ns + window) continue;
    bool stays = true;
    for (std::size_t j = i; j < errors.size() && errors[j].time_ns <= e.time_ns + window; ++j) {
      if (errors[j].pos_ned_m.head<2>().norm() >= threshold_m) {
        stays = false;
        break;
      }
    }
    if (stays) return 1e-9 * static_cast<double>(e.time_ns - t0_ns);
  }
  return std::nan("");
}

double chiSquareQuantile(double p, double dof) {
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), p);
}

int runOfflineCommand(const OfflineOptions& o) {
  OfflineSetup setup = loadSetup(o.scenario, filterYaml(o.filter, o.align), o.filter, o.seed,
                                 o.duration_s, o.fault_manager);
  setup.keep_lane_solutions = !setup.filter.lanes.units.empty();  // lanes.csv
  std::filesystem::create_directories(o.out_dir);
  std::ofstream sol_f(o.out_dir + "/solution.csv"), truth_f(o.out_dir + "/truth.csv"),
      err_f(o.out_dir + "/error.csv");
  if (!sol_f || !truth_f || !err_f) {
    throw bus::ConfigError("cannot write into --out " + o.out_dir);
  }
  sol_f << records::csvHeader<navbus::NavigationSolution>() << "\n";
  writeTruthHeader(truth_f);
  writeErrorHeader(err_f);
  {
    // The truth at the start, in the units of the filter configuration's initial_state.
    const core::NavState t0 = initialTruth(setup.sim.scenario);
    const Eigen::Vector3d rpy = core::eulerFromDcm(t0.q_b_to_n.toRotationMatrix()) * 180.0 / M_PI;
    spdlog::info(
        "scenario start (truth): latitude_deg {:.9f}, longitude_deg {:.9f}, height_m {:.3f}, "
        "vel_ned_mps [{:.6f}, {:.6f}, {:.6f}], roll_deg {:.6f}, pitch_deg {:.6f}, yaw_deg {:.6f}",
        t0.position.latitude_rad * 180.0 / M_PI, t0.position.longitude_rad * 180.0 / M_PI,
        t0.position.height_m, t0.vel_ned_mps.x(), t0.vel_ned_mps.y(), t0.vel_ned_mps.z(), rpy.x(),
        rpy.y(), rpy.z());
  }
  // Lines go into buffers, flushed in blocks (the files are tens of MB for an hour of data).
  fmt::memory_buffer sol_b, truth_b, err_b;
  const auto flush = [&](std::size_t above) {
    for (auto [buf, file] : {std::pair{&sol_b, &sol_f}, {&truth_b, &truth_f}, {&err_b, &err_f}}) {
      if (buf->size() <= above) continue;
      file->write(buf->data(), static_cast<std::streamsize>(buf->size()));
      buf->clear();
    }
  };
  const auto out = [](fmt::memory_buffer& b) { return fmt::appender(b); };
  const OfflineResult r = runOffline(setup, [&](const navbus::NavigationSolution& s,
                                                const core::NavState& t, const EpochError& e) {
    if (!records::appendCsvLine(s, sol_b)) {
      for (const auto& row : records::csvRows(s))
        fmt::format_to(out(sol_b), FMT_COMPILE("{}\n"), row);
    }
    const Eigen::Vector3d rpy = core::eulerFromDcm(t.q_b_to_n.toRotationMatrix());
    fmt::format_to(out(truth_b), FMT_COMPILE("{},{},{},{},{},{},{},{},{},{}\n"), t.time_ns,
                   t.position.latitude_rad, t.position.longitude_rad, t.position.height_m,
                   t.vel_ned_mps.x(), t.vel_ned_mps.y(), t.vel_ned_mps.z(), rpy.x(), rpy.y(),
                   rpy.z());
    fmt::format_to(out(err_b), FMT_COMPILE("{},{}"), e.time_ns, e.mode);
    for (const Eigen::Vector3d* v :
         {&e.pos_ned_m, &e.vel_ned_mps, &e.att_ned_rad, &e.pos_sigma_ned_m, &e.vel_sigma_ned_mps,
          &e.att_sigma_ned_rad}) {
      fmt::format_to(out(err_b), FMT_COMPILE(",{},{},{}"), v->x(), v->y(), v->z());
    }
    fmt::format_to(out(err_b), FMT_COMPILE(",{}"), e.nees9);
    for (const Eigen::Vector3d* v :
         {&e.accel_bias_err_b_mps2, &e.gyro_bias_err_b_radps, &e.star_tracker_bias_err_b_rad}) {
      fmt::format_to(out(err_b), FMT_COMPILE(",{},{},{}"), v->x(), v->y(), v->z());
    }
    // Empty: a block the filter does not estimate.
    for (int b = 0; b < kNeesBlocks; ++b) {
      if (std::isnan(e.nees_blocks[b]))
        fmt::format_to(out(err_b), FMT_COMPILE(","));
      else
        fmt::format_to(out(err_b), FMT_COMPILE(",{}"), e.nees_blocks[b]);
    }
    fmt::format_to(out(err_b), FMT_COMPILE("\n"));
    flush(1 << 20);
  });
  flush(0);
  if (!sol_f || !truth_f || !err_f) throw bus::ConfigError("cannot write into --out " + o.out_dir);
  spdlog::info("offline: scenario '{}' seed {}: {} solutions ({} without a truth sample); {}",
               setup.sim.scenario.name, setup.sim.scenario.seed, r.solutions,
               r.solutions_without_truth, r.summary);
  if (setup.fault_manager) {
    if (!records::writeCsvFile(o.out_dir + "/decisions.csv", r.decisions) ||
        !records::writeCsvFile(o.out_dir + "/commands.csv", r.commands) ||
        !writeGlrCsv(o.out_dir + "/glr.csv", r.glr_trace))
      spdlog::error("could not write decisions.csv / commands.csv / glr.csv in {}", o.out_dir);
    if (!r.parity_trace.empty() && !writeParityCsv(o.out_dir + "/parity.csv", r.parity_trace))
      spdlog::error("could not write parity.csv in {}", o.out_dir);
    if (!r.lane_solutions.empty() &&
        !records::writeCsvFile(o.out_dir + "/lanes.csv", r.lane_solutions))
      spdlog::error("could not write lanes.csv in {}", o.out_dir);
    spdlog::info("fault manager: {}", r.fault_summary);
    spdlog::info(
        "wrote {}/solution.csv, truth.csv, error.csv, decisions.csv, commands.csv, glr.csv{}{}",
        o.out_dir, r.parity_trace.empty() ? "" : ", parity.csv",
        r.lane_solutions.empty() ? "" : ", lanes.csv");
  } else {
    spdlog::info("wrote {}/solution.csv, truth.csv, error.csv", o.out_dir);
  }
  return bus::kExitOk;
}

namespace {

/// One row of the tables: a filter file with its overrides (fusion, policy).
struct Variant {
  std::string label;
  YAML::Node yaml;
  std::string path;
};

/// Set-up: every filter file times every --fusion and --policy override.
std::vector<Variant> monteCarloVariants(const MonteCarloOptions& o) {
  std::vector<Variant> variants;
  const auto orEmpty = [](const std::vector<std::string>& v) {
    return v.empty() ? std::vector<std::string>{""} : v;
  };
  for (const std::string& file : o.filters) {
    const std::string stem = std::filesystem::path(file).stem().string();
    for (const auto& fu : orEmpty(o.fusions)) {
      for (const auto& po : orEmpty(o.policies)) {
        YAML::Node y = filterYaml(file, o.align);
        std::string label = stem;
        if (!fu.empty()) {
          y["fusion"] = fu;
          label += " " + fu;
        }
        if (!po.empty()) {
          y["multi_dimensional"]["policy"] = po;
          label += " " + po;
        }
        variants.push_back({label, y, file});
      }
    }
  }
  return variants;
}

/// Set-up: one offline run per seed, the initial state drawn (or the truth) unless it aligns.
std::vector<OfflineSetup> monteCarloSetups(const MonteCarloOptions& o, const Variant& v) {
  std::vector<OfflineSetup> setups(static_cast<std::size_t>(o.runs));
  for (int i = 0; i < o.runs; ++i) {
    const std::uint64_t seed = o.first_seed + static_cast<std::uint64_t>(i);
    OfflineSetup& setup = setups[static_cast<std::size_t>(i)];
    setup = loadSetup(o.scenario, v.yaml, v.path, seed, o.duration_s, o.fault_manager);
    if (setup.filter.engine.start == core::StartSource::kAligned) continue;
    const core::NavState truth0 = initialTruth(setup.sim.scenario);
    setup.filter.engine.initial_state =
        o.perturb_initial
            ? perturbedInitialState(truth0, setup.filter.engine.tuning, seed * 1000003ull + 17ull)
            : truth0;
  }
  return setups;
}

/// Tallies of one configuration over its runs: each tally takes every run (add), the report
/// prints them. A new tally (a lane's, say) is a member here and a line in add().
struct Tallies {
  std::string label;
  Stats st;
  std::vector<AlignmentOutcome> alignments;  ///< one per run, filters that aligned
  IntegrityTally integrity;                  ///< protection levels against the errors
  HonestyTally honesty;                      ///< the filter's own claims
  std::optional<sim::Fault> fault;           ///< the detectable fault, with a fault manager
  std::vector<FaultRunOutcome> fault_runs;   ///< one per run, with a fault manager
  double hours{0.0};                         ///< of data per run

  void add(const MonteCarloOptions& o, const OfflineSetup& setup, const OfflineResult& r,
           std::uint64_t seed) {
    const std::int64_t start = setup.sim.scenario.start_time_ns;
    accumulate(st, r, start + static_cast<std::int64_t>(std::llround(o.from_s * 1e9)), o, start);
    integrity.add(r, seed);
    honesty.add(r, setup.filter.engine.consistency.false_alarm_probability);
    if (setup.filter.engine.start == core::StartSource::kAligned)
      alignments.push_back({r.aligned, r.aligned_start, r.aligned_start_error,
                            1e-9 * static_cast<double>(r.aligned_start.state.time_ns - start)});
    if (setup.fault_manager) {
      fault = detectableFault(setup.sim.scenario.faults);
      fault_runs.push_back(evaluateRun(r, fault, start, seed));
    }
    hours = setup.duration_s / 3600.0;
  }
};

/// The average NEES's 95 % band for `runs` runs of 9 degrees of freedom.
struct NeesBand {
  double lo, hi;
};
NeesBand neesBand(int runs) {
  const double dof = 9.0;
  return {chiSquareQuantile(0.025, dof * runs) / runs, chiSquareQuantile(0.975, dof * runs) / runs};
}

void printErrorTable(const std::vector<Tallies>& rows, const MonteCarloOptions& o) {
  const NeesBand band = neesBand(o.runs);
  std::printf("\nerrors from %.0f s; RMS and max of the 3-D error norms over all epochs and runs\n",
              o.from_s);
  std::printf("%-34s %9s %9s %10s %10s %10s %10s %8s %16s %8s\n", "configuration", "pos RMS m",
              "pos max m", "vel RMS m/s", "vel max", "att RMS \"", "att max \"", "NEES(9)",
              "95% band", "in band");
  for (const Tallies& r : rows) {
    const Stats& s = r.st;
    const double n = static_cast<double>(s.n > 0 ? s.n : 1);
    double nees_mean = 0;
    int in_band = 0, epochs = 0;
    for (std::size_t k = 0; k < s.nees_sum.size(); ++k) {
      if (s.nees_runs[k] != o.runs) continue;  // epochs every run reached
      const double avg = s.nees_sum[k] / o.runs;
      nees_mean += avg;
      in_band += (avg >= band.lo && avg <= band.hi) ? 1 : 0;
      ++epochs;
    }
    nees_mean /= std::max(epochs, 1);
    std::printf("%-34s %9.3f %9.3f %10.4f %10.4f %10.2f %10.2f %8.2f [%6.2f,%6.2f] %7.1f%%\n",
                r.label.c_str(), std::sqrt(s.sum_pos2 / n), s.max_pos, std::sqrt(s.sum_vel2 / n),
                s.max_vel, std::sqrt(s.sum_att2 / n) * kArcsecPerRad, s.max_att * kArcsecPerRad,
                nees_mean, band.lo, band.hi, 100.0 * in_band / std::max(epochs, 1));
  }
}

void writeMonteCarloCsvs(const std::vector<Tallies>& rows, const MonteCarloOptions& o) {
  const NeesBand band = neesBand(o.runs);
  std::filesystem::create_directories(o.csv_dir);
  std::ofstream nees(o.csv_dir + "/nees.csv");
  nees << "configuration,time_s,nees9_mean,band_low,band_high,runs\n";
  for (const Tallies& r : rows) writeNeesCsv(nees, r.label, r.st, o.runs, band.lo, band.hi);
  std::string written = o.csv_dir + "/nees.csv";
  bool ok = static_cast<bool>(nees);
  const bool faults_run =
      std::any_of(rows.begin(), rows.end(), [](const Tallies& r) { return !r.fault_runs.empty(); });
  if (faults_run) {
    std::ofstream faults(o.csv_dir + "/faults.csv");
    faults << "configuration,seed,fault_s,detected,detection_s,delay_s,onset_s,class_correct,"
              "source_correct,ambiguous,false_alarms,recovery_s,decided,decisions\n";
    for (const Tallies& r : rows) {
      if (!r.fault_runs.empty()) writeFaultRunsCsv(faults, r.label, r.fault, r.fault_runs);
    }
    ok = ok && static_cast<bool>(faults);
    written += ", faults.csv";
  }
  if (!ok) throw bus::ConfigError("cannot write the CSV files into --csv " + o.csv_dir);
  std::printf("\nwrote %s\n", written.c_str());
}

void printRecoveryTable(const std::vector<Tallies>& rows, const MonteCarloOptions& o) {
  std::printf(
      "\nconvergence after each instant: median over runs of the time until the "
      "horizontal position error stays below %.2f m for %.0f s; runs that do not converge "
      "within the window (count in brackets) count as slowest\n",
      o.recovery_threshold_m, o.recovery_window_s);
  std::printf("%-34s", "configuration");
  for (double t : o.recovery_after_s) std::printf("   after %5.1f s", t);
  std::printf("\n");
  for (const Tallies& r : rows) {
    std::printf("%-34s", r.label.c_str());
    const std::size_t m = o.recovery_after_s.size();
    for (std::size_t j = 0; j < m; ++j) {
      std::vector<double> v;
      int missing = 0;
      for (std::size_t i = j; i < r.st.recovery_s.size(); i += m) {
        v.push_back(r.st.recovery_s[i]);
        missing += std::isnan(r.st.recovery_s[i]) ? 1 : 0;
      }
      const double med = median(v);
      if (std::isinf(med)) {
        std::printf("   %6s%4.0f s (%d)", ">", o.recovery_window_s, missing);
      } else {
        std::printf("   %8.2f s (%d)", med, missing);
      }
    }
    std::printf("\n");
  }
}

/// Report: every table of the tallies, then the CSV files.
void report(const std::vector<Tallies>& rows, const MonteCarloOptions& o) {
  printErrorTable(rows, o);
  printBlockNees(rows, o.runs);
  for (const Tallies& r : rows) {
    if (!r.alignments.empty()) printAlignment(r.label, r.alignments);
  }
  for (const Tallies& r : rows) {
    if (!r.fault_runs.empty()) printFaultTable(r.label, r.fault, r.fault_runs, r.hours);
  }
  std::vector<std::pair<std::string, IntegrityTally>> integrity;
  std::vector<std::pair<std::string, HonestyTally>> honesty;
  for (const Tallies& r : rows) {
    integrity.emplace_back(r.label, r.integrity);
    honesty.emplace_back(r.label, r.honesty);
  }
  printIntegrityTable(integrity);
  printHonestyTable(honesty);
  if (!o.csv_dir.empty()) writeMonteCarloCsvs(rows, o);
  if (!o.recovery_after_s.empty()) printRecoveryTable(rows, o);
}

}  // namespace

int runMonteCarloCommand(const MonteCarloOptions& o) {
  const std::vector<Variant> variants = monteCarloVariants(o);
  std::printf(
      "Monte Carlo: scenario %s, %d runs per configuration (seeds %llu..%llu)%s\n",
      o.scenario.c_str(), o.runs, static_cast<unsigned long long>(o.first_seed),
      static_cast<unsigned long long>(o.first_seed + static_cast<std::uint64_t>(o.runs) - 1),
      o.align             ? ", every filter aligned from its inputs"
      : o.perturb_initial ? ", initial state drawn from the filter's initial sigmas (filters "
                            "without an initial_state align)"
                          : "");
  std::vector<Tallies> rows;
  for (const Variant& v : variants) {
    const std::vector<OfflineSetup> setups = monteCarloSetups(o, v);
    const std::vector<OfflineResult> results = runInParallel(setups, o.threads, v.label);
    Tallies& row = rows.emplace_back();
    row.label = v.label;
    for (std::size_t i = 0; i < setups.size(); ++i)
      row.add(o, setups[i], results[i], o.first_seed + i);
  }
  report(rows, o);
  return bus::kExitOk;
}

}  // namespace navbus::evaluation
