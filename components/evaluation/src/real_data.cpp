#include "navbus/evaluation/real_data.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <spdlog/spdlog.h>

#include "navbus/bus/app.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/evaluation/fault_evaluation.hpp"
#include "navbus/fault_manager/fault_pipeline.hpp"
#include "navbus/records/formatters.hpp"

namespace navbus::evaluation {

namespace {

using core::earth::Geodetic;

std::int64_t toNs(double gps_s) {
  return std::llround(gps_s * 1e9);
}

/// Which satellites' pseudoranges the fault manager's commands have excluded, and when.
class Exclusions {
 public:
  void exclude(int sv, double after_s) {
    intervals_.push_back({sv, after_s, std::numeric_limits<double>::infinity()});
  }
  void readmit(int sv, double after_s) {
    for (Interval& i : intervals_) {
      if (i.sv == sv && std::isinf(i.until_s)) i.until_s = after_s;
    }
  }
  bool excluded(int sv, double t_s) const {
    return std::any_of(intervals_.begin(), intervals_.end(), [&](const Interval& i) {
      return i.sv == sv && t_s > i.from_s && t_s <= i.until_s;
    });
  }

 private:
  struct Interval {
    int sv;
    double from_s, until_s;  ///< excluded for from < t <= until
  };
  std::vector<Interval> intervals_;
};

/// The filter's inputs of one epoch, kept to re-process from an onset.
struct FilterInput {
  double time_s;
  std::vector<core::SatelliteObservation> sats;
};

class RealDataRun {
 public:
  explicit RealDataRun(const RealDataSetup& s)
      : setup_(s),
        reference_(core::earth::ecefToGeodetic(s.reference_ecef_m)),
        health_("navbus-rinex") {
    if (s.fault_manager) {
      faults_.emplace(
          *s.fault_manager, health_,
          fault_manager::FaultPipeline::Sinks{
              [this](const navbus::FaultDecision& d) { result_.decisions.push_back(d); },
              [this](const navbus::FilterCommand& c) { onCommand(c); }});
    }
  }

  RealDataResult run() {
    const int type = setup_.obs.typeIndex(setup_.observable);
    if (type < 0) {
      throw bus::ConfigError("observation file has no '" + setup_.observable +
                             "' observable (types: " + std::to_string(setup_.obs.types.size()) +
                             ")");
    }
    for (const gnss_data::RinexObservationEpoch& e : setup_.obs.epochs) processEpoch(e, type);
    if (faults_) {
      result_.fault_summary = faults_->summary();
      result_.max_glr_statistic = faults_->glr().counters().max_statistic;
    }
    return std::move(result_);
  }

 private:
  void processEpoch(const gnss_data::RinexObservationEpoch& e, int type) {
    gnss_data::EpochPseudoranges raw = gnss_data::pseudoranges(e, type);
    result_.other_systems += static_cast<std::uint64_t>(raw.other_systems);
    result_.missing += static_cast<std::uint64_t>(raw.missing);
    inject(e.time_s, raw.observations);
    RealDataEpoch out;
    out.time_ns = toNs(e.time_s);
    out.satellites = static_cast<int>(raw.observations.size());
    const core::SinglePointSolution fix =
        core::solveSinglePoint(e.time_s, raw.observations, setup_.nav.ephemerides, setup_.nav.iono,
                               setup_.spp, last_fix_ecef_m_);
    countRejections(fix);
    if (fix.valid) {
      ++result_.fixes;
      last_fix_ecef_m_ = fix.pos_ecef_m;
      out.fix_valid = true;
      out.fix_used = fix.used;
      out.fix_ecef_m = fix.pos_ecef_m;
      out.fix_clock_bias_m = fix.clock_bias_m;
      out.fix_error_ned_m = errorNed(fix.pos_ecef_m);
      if (!filter_.initialized()) {
        start_ = {fix.pos_ecef_m, fix.clock_bias_m, e.time_s};
        filter_.initialize(start_.pos, start_.clock, start_.time_s, setup_.filter);
      }
      history_.push_back({e.time_s, correctedObservations(fix)});
      filterEpoch(history_.back(), true);
    } else {
      ++result_.no_fix;
    }
    if (filter_.initialized()) {
      out.filtered = fix.valid;
      out.filter_error_ned_m = errorNed(filter_.positionEcef());
      out.filter_sigma_ned_m = filter_.positionCovarianceNed().diagonal().cwiseSqrt();
      out.filter_rows_used = static_cast<int>(
          std::count(filter_.lastEpoch().used.begin(), filter_.lastEpoch().used.end(), true));
    }
    result_.epochs.push_back(out);
  }

  void inject(double t_s, std::vector<core::PseudorangeObservation>& obs) {
    if (!setup_.ramp || setup_.obs.epochs.empty()) return;
    const double dt = t_s - setup_.obs.epochs.front().time_s - setup_.ramp->onset_after_start_s;
    if (dt <= 0.0) return;
    for (core::PseudorangeObservation& o : obs) {
      if (o.sv_id != setup_.ramp->sv_id) continue;
      o.pseudorange_m += setup_.ramp->rate_mps * dt;
      ++result_.injected_epochs;
    }
  }

  void countRejections(const core::SinglePointSolution& fix) {
    for (const core::SinglePointSatellite& s : fix.satellites) {
      if (s.use == core::SatelliteUse::kBelowMask) ++result_.below_mask;
      if (s.use == core::SatelliteUse::kNoEphemeris) ++result_.no_ephemeris;
      if (s.use == core::SatelliteUse::kBadRange) ++result_.bad_range;
    }
  }

  static std::vector<core::SatelliteObservation> correctedObservations(
      const core::SinglePointSolution& fix) {
    std::vector<core::SatelliteObservation> sats;
    for (const core::SinglePointSatellite& s : fix.satellites) {
      if (s.use == core::SatelliteUse::kUsed) sats.push_back(s.corrected);
    }
    return sats;
  }

  /// One filter epoch with the current exclusions; `monitor`: its diagnostics go to the GLR.
  void filterEpoch(FilterInput input, bool monitor) {
    for (core::SatelliteObservation& s : input.sats) {
      s.use_range = !exclusions_.excluded(s.sv_id, input.time_s);
    }
    const core::EpochDiagnostics& d = filter_.update(input.time_s, input.sats);
    if (monitor && faults_) {
      if (faults_->onDiagnostics(bus::toIdl(d, setup_.fault_manager->vehicle_id, ++diagnostics_seq_,
                                            toNs(input.time_s))))
        result_.glr_trace.push_back(faults_->glr().latest());
    }
  }

  void onCommand(const navbus::FilterCommand& c) {
    result_.commands.push_back(c);
    const double t_s = static_cast<double>(c.time_gps_ns()) * 1e-9;
    switch (c.kind()) {
      case navbus::CMD_EXCLUDE_SATELLITE:
        if (c.scope() == navbus::SCOPE_PSEUDORANGE_RATE) {
          ++result_.commands_not_applicable;  // no rates from this receiver
          return;
        }
        // Contaminated since the onset: exclude from there and re-process (deterministic).
        exclusions_.exclude(c.sv_id(), static_cast<double>(c.onset_time_gps_ns()) * 1e-9);
        reprocess();
        return;
      case navbus::CMD_READMIT_SATELLITE:
        exclusions_.readmit(c.sv_id(), t_s);
        return;
      default:
        ++result_.commands_not_applicable;  // IMU biases, fusion, streams: none here
    }
  }

  /// Re-runs the filter over the kept inputs with the exclusions now known; the GLR is not
  /// shown these epochs again (it has seen them once, as on the bus).
  void reprocess() {
    ++result_.reprocessings;
    filter_.initialize(start_.pos, start_.clock, start_.time_s, setup_.filter);
    for (const FilterInput& in : history_) filterEpoch(in, false);
  }

  Eigen::Vector3d errorNed(const Eigen::Vector3d& ecef) const {
    return core::earth::differenceNed(core::earth::ecefToGeodetic(ecef), reference_);
  }

  const RealDataSetup& setup_;
  Geodetic reference_;
  bus::HealthCounters health_;
  std::optional<fault_manager::FaultPipeline> faults_;
  core::StaticReceiverFilter filter_;
  struct Start {
    Eigen::Vector3d pos{Eigen::Vector3d::Zero()};
    double clock{0.0};
    double time_s{0.0};
  } start_;
  std::vector<FilterInput> history_;
  Exclusions exclusions_;
  Eigen::Vector3d last_fix_ecef_m_{Eigen::Vector3d::Zero()};
  std::uint64_t diagnostics_seq_{0};
  RealDataResult result_;
};

}  // namespace

RealDataResult runRealData(const RealDataSetup& setup) {
  return RealDataRun(setup).run();
}

namespace {

template <class T>
T readFile(const std::string& path, T (*reader)(std::istream&, const std::string&)) {
  std::ifstream in(path);
  if (!in) throw bus::ConfigError("cannot open " + path);
  return reader(in, path);
}

double rms(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return v.empty() ? 0.0 : std::sqrt(s / static_cast<double>(v.size()));
}

void writeFixes(const std::string& path, const RealDataResult& r) {
  std::ofstream f(path);
  f << "time_gps_ns,satellites,fix_valid,fix_used,fix_ecef_m[0],fix_ecef_m[1],fix_ecef_m[2],"
       "fix_clock_bias_m,fix_err_ned_m[0],fix_err_ned_m[1],fix_err_ned_m[2],filtered,"
       "filter_rows_used,filter_err_ned_m[0],filter_err_ned_m[1],filter_err_ned_m[2],"
       "filter_sigma_ned_m[0],filter_sigma_ned_m[1],filter_sigma_ned_m[2]\n";
  auto v3 = [&f](const Eigen::Vector3d& v) {
    f << "," << records::formatNumber(v.x()) << "," << records::formatNumber(v.y()) << ","
      << records::formatNumber(v.z());
  };
  for (const RealDataEpoch& e : r.epochs) {
    f << e.time_ns << "," << e.satellites << "," << e.fix_valid << "," << e.fix_used;
    v3(e.fix_ecef_m);
    f << "," << records::formatNumber(e.fix_clock_bias_m);
    v3(e.fix_error_ned_m);
    f << "," << e.filtered << "," << e.filter_rows_used;
    v3(e.filter_error_ned_m);
    v3(e.filter_sigma_ned_m);
    f << "\n";
  }
}

void writeFaultCsv(const std::string& dir, const RealDataResult& r) {
  if (!records::writeCsvFile(dir + "/decisions.csv", r.decisions) ||
      !records::writeCsvFile(dir + "/commands.csv", r.commands) ||
      !writeGlrCsv(dir + "/glr.csv", r.glr_trace))
    spdlog::error("could not write decisions.csv / commands.csv / glr.csv in {}", dir);
}

void printSummary(const RealDataSetup& s, const RealDataResult& r) {
  std::vector<double> n, e, d, d3;
  Eigen::Vector3d mean_ecef = Eigen::Vector3d::Zero();
  for (const RealDataEpoch& x : r.epochs) {
    if (!x.fix_valid) continue;
    n.push_back(x.fix_error_ned_m.x());
    e.push_back(x.fix_error_ned_m.y());
    d.push_back(x.fix_error_ned_m.z());
    d3.push_back(x.fix_error_ned_m.norm());
    mean_ecef += x.fix_ecef_m - s.reference_ecef_m;
  }
  if (!d3.empty()) mean_ecef /= static_cast<double>(d3.size());
  std::printf(
      "least squares: %llu fixes, %llu epochs without; mean error ECEF (%.2f, %.2f, %.2f) "
      "m; RMS north %.2f east %.2f down %.2f m, 3D %.2f m\n",
      static_cast<unsigned long long>(r.fixes), static_cast<unsigned long long>(r.no_fix),
      mean_ecef.x(), mean_ecef.y(), mean_ecef.z(), rms(n), rms(e), rms(d), rms(d3));
  std::printf(
      "satellites not used (over all epochs): %llu below the elevation mask, %llu without "
      "ephemeris, %llu with an implausible range, %llu of other systems, %llu without %s\n",
      static_cast<unsigned long long>(r.below_mask),
      static_cast<unsigned long long>(r.no_ephemeris), static_cast<unsigned long long>(r.bad_range),
      static_cast<unsigned long long>(r.other_systems), static_cast<unsigned long long>(r.missing),
      s.observable.c_str());
  if (!r.epochs.empty() && r.epochs.back().filtered) {
    const RealDataEpoch& last = r.epochs.back();
    std::printf(
        "static filter, last epoch: error NED (%.2f, %.2f, %.2f) m, sigma (%.2f, %.2f, "
        "%.2f) m, %d pseudoranges fused\n",
        last.filter_error_ned_m.x(), last.filter_error_ned_m.y(), last.filter_error_ned_m.z(),
        last.filter_sigma_ned_m.x(), last.filter_sigma_ned_m.y(), last.filter_sigma_ned_m.z(),
        last.filter_rows_used);
  }
  if (!s.fault_manager) return;
  std::printf("fault manager: %s\n", r.fault_summary.c_str());
  std::printf(
      "GLR: largest statistic %.2f (threshold %.3f), %zu decisions, %zu commands, %llu "
      "re-processings from an onset, %llu commands not applicable to a static receiver\n",
      r.max_glr_statistic, s.fault_manager->glr.glr.threshold, r.decisions.size(),
      r.commands.size(), static_cast<unsigned long long>(r.reprocessings),
      static_cast<unsigned long long>(r.commands_not_applicable));
  const double start_s = s.obs.epochs.empty() ? 0.0 : s.obs.epochs.front().time_s;
  for (const navbus::FaultDecision& dec : r.decisions) {
    std::printf(
        "  decision %u at %.0f s: %s sv %u, statistic %.1f, magnitude %.3f, onset after "
        "%.0f s%s\n",
        dec.decision_id(), static_cast<double>(dec.time_gps_ns()) * 1e-9 - start_s,
        dec.detector().c_str(), dec.sv_id(), dec.test_statistic(), dec.magnitude(),
        static_cast<double>(dec.onset_time_gps_ns()) * 1e-9 - start_s,
        dec.ambiguous() ? " (ambiguous)" : "");
  }
}

}  // namespace

int runRealDataCommand(const RealDataOptions& o) {
  RealDataSetup s;
  try {
    s.obs = readFile(o.obs, &gnss_data::readObservationFile);
    s.nav = readFile(o.nav, &gnss_data::readNavigationFile);
  } catch (const gnss_data::RinexError& e) {
    spdlog::error("{}", e.what());
    return bus::kExitConfigError;
  }
  if (!s.nav.has_iono) {
    spdlog::warn("{} has no ION ALPHA/BETA: the broadcast ionosphere model is zero", o.nav);
  }
  if (o.reference.empty()) {
    s.reference_ecef_m = s.obs.approx_position_ecef_m;
  } else if (o.reference.size() == 3) {
    s.reference_ecef_m = {o.reference[0], o.reference[1], o.reference[2]};
  } else {
    throw bus::ConfigError("--reference takes x,y,z (3 values), got " +
                           std::to_string(o.reference.size()));
  }
  if (!o.ramp.empty()) {
    if (o.ramp.size() != 3 || o.ramp[0] < 1 || o.ramp[0] > 32 || o.ramp[0] != std::floor(o.ramp[0]))
      throw bus::ConfigError("--inject-ramp takes sv,rate_mps,onset_s with sv 1..32");
    s.ramp = RampInjection{static_cast<int>(o.ramp[0]), o.ramp[1], o.ramp[2]};
  }
  if (!o.fault_manager.empty()) {
    s.fault_manager = bus::parseFile(o.fault_manager, fault_manager::parseFaultManagerConfig);
  }
  const RealDataResult r = runRealData(s);
  if (s.ramp && r.injected_epochs == 0) {
    throw bus::ConfigError("--inject-ramp: sv " + std::to_string(s.ramp->sv_id) + " has no " +
                           s.observable + " observation after " +
                           std::to_string(s.ramp->onset_after_start_s) + " s");
  }
  std::printf(
      "real data: %s (marker '%s'), %zu epochs, observable %s; reference ECEF (%.4f, "
      "%.4f, %.4f) m%s\n",
      o.obs.c_str(), s.obs.marker.c_str(), s.obs.epochs.size(), s.observable.c_str(),
      s.reference_ecef_m.x(), s.reference_ecef_m.y(), s.reference_ecef_m.z(),
      o.reference.empty() ? " (the header's APPROX POSITION XYZ)" : "");
  if (s.ramp) {
    std::printf(
        "injected: ramp %.3f m/s on sv %d from %.0f s after the first epoch (%llu "
        "epochs)\n",
        s.ramp->rate_mps, s.ramp->sv_id, s.ramp->onset_after_start_s,
        static_cast<unsigned long long>(r.injected_epochs));
  }
  printSummary(s, r);
  std::fflush(stdout);
  std::filesystem::create_directories(o.out_dir);
  writeFixes(o.out_dir + "/fixes.csv", r);
  if (s.fault_manager) writeFaultCsv(o.out_dir, r);
  spdlog::info("wrote {}/fixes.csv{}", o.out_dir,
               s.fault_manager ? ", decisions.csv, commands.csv, glr.csv" : "");
  return bus::kExitOk;
}

}  // namespace navbus::evaluation
