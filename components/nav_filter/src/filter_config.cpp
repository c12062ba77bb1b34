#include "navbus/nav_filter/filter_config.hpp"

#include <algorithm>

#include <cmath>

#include "navbus/bus/config.hpp"
#include "navbus/core/filter/innovation_window.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"

namespace navbus::nav_filter {

namespace {
std::int64_t seconds(double s) {
  return std::llround(s * 1e9);
}

std::optional<InputConfig> input(const YAML::Node& inputs, const std::string& key, bool required) {
  const YAML::Node n = inputs[key];
  if (!n) {
    if (required) throw bus::ConfigError("configuration inputs." + key + " is missing");
    return std::nullopt;
  }
  const std::string where = "inputs." + key;
  bus::checkKeys(n, where, {"id", "period_s"});
  InputConfig c;
  c.id = bus::require<std::uint32_t>(n, where, "id");
  c.period_ns = seconds(
      bus::checkRange(bus::require<double>(n, where, "period_s"), 1e-4, 60.0, where + ".period_s"));
  return c;
}
}  // namespace

namespace {
template <class Enum>
Enum choice(const YAML::Node& node, const std::string& where, const std::string& key,
            const std::string& fallback, std::initializer_list<std::pair<const char*, Enum>> opts) {
  const std::string v = bus::get<std::string>(node, where, key, fallback);
  std::string names;
  for (const auto& [name, value] : opts) {
    if (v == name) return value;
    names += names.empty() ? name : std::string(" | ") + name;
  }
  const std::string full = where.empty() ? key : where + "." + key;
  throw bus::ConfigError("configuration " + full + " = '" + v + "' is not one of " + names);
}
}  // namespace

namespace {
void parseInitialState(const YAML::Node& init, core::NavState& s) {
  bus::checkKeys(init, "initial_state",
                 {"latitude_deg", "longitude_deg", "height_m", "vel_ned_mps", "roll_deg",
                  "pitch_deg", "yaw_deg"});
  s.position = bus::getGeodeticDeg(init, "initial_state", nullptr);
  s.vel_ned_mps = bus::getVector3(init, "initial_state", "vel_ned_mps", 1.0);
  const Eigen::Vector3d rpy = bus::getRollPitchYawDeg(init, "initial_state");
  s.q_b_to_n = Eigen::Quaterniond(core::dcmFromEuler(rpy));
}

/// The alignment (used without an initial_state). Its error budget is the filter's own tuning
/// (bias sigmas, noise densities), and "at rest" is multi_dimensional.stationary: one place
/// each.
void parseAlignment(const YAML::Node& node, core::EngineConfig& e) {
  const std::string w = "alignment";
  bus::checkKeys(node, w,
                 {"static_window_s", "min_static_window_s", "max_heading_sigma_deg",
                  "course_min_speed_mps", "course_sigma_deg", "course_check_heading_sigma_deg"});
  core::InitialAlignmentConfig& a = e.alignment;
  const core::FilterTuning& t = e.tuning;
  a.budget.accel_bias_sigma_mps2 = t.accel_bias_sigma_mps2;
  a.budget.gyro_bias_sigma_radps = t.gyro_bias_sigma_radps;
  a.budget.velocity_random_walk_mps_per_sqrts = t.accel_noise_mps2_per_sqrthz;
  a.budget.angle_random_walk_rad_per_sqrts = t.gyro_noise_radps_per_sqrthz;
  a.rest = e.mdf.stationarity;
  a.imu_period_s = e.imu_period_s;
  a.static_window_s =
      bus::checkRange(bus::get<double>(node, w, "static_window_s", a.static_window_s), 1.0, 3600.0,
                      "alignment.static_window_s");
  a.min_static_window_s =
      bus::checkRange(bus::get<double>(node, w, "min_static_window_s", a.min_static_window_s), 0.1,
                      a.static_window_s, "alignment.min_static_window_s");
  a.max_heading_sigma_rad = bus::checkRange(bus::get<double>(node, w, "max_heading_sigma_deg",
                                                             a.max_heading_sigma_rad / units::kDeg),
                                            0.0, 180.0, "alignment.max_heading_sigma_deg") *
                            units::kDeg;
  a.course_min_speed_mps =
      bus::checkRange(bus::get<double>(node, w, "course_min_speed_mps", a.course_min_speed_mps),
                      0.1, 1e4, "alignment.course_min_speed_mps");
  a.course_sigma_rad = bus::checkRange(bus::get<double>(node, w, "course_sigma_deg",
                                                        a.course_sigma_rad / units::kDeg),
                                       1e-3, 90.0, "alignment.course_sigma_deg") *
                       units::kDeg;
  a.course_check_heading_sigma_rad =
      bus::checkRange(bus::get<double>(node, w, "course_check_heading_sigma_deg",
                                       a.course_check_heading_sigma_rad / units::kDeg),
                      0.0, 180.0, "alignment.course_check_heading_sigma_deg") *
      units::kDeg;
}

/// Protection levels (tightly coupled): the risks, the alert limits and the GLR the fault
/// manager runs (its statistics keys, as in the fault manager's `glr` block).
void parseIntegrity(const YAML::Node& node, core::EngineConfig& e) {
  const std::string w = "integrity";
  bus::checkKeys(node, w,
                 {"enabled", "integrity_risk", "missed_detection_probability",
                  "horizontal_alert_limit_m", "vertical_alert_limit_m", "detector"});
  core::IntegrityConfig& i = e.integrity;
  i.enabled = bus::get<bool>(node, w, "enabled", static_cast<bool>(node));
  i.integrity_risk = bus::checkRange(bus::get<double>(node, w, "integrity_risk", i.integrity_risk),
                                     1e-15, 0.1, "integrity.integrity_risk");
  i.missed_detection_probability = bus::checkRange(
      bus::get<double>(node, w, "missed_detection_probability", i.missed_detection_probability),
      1e-12, 0.5, "integrity.missed_detection_probability");
  i.horizontal_alert_limit_m = bus::checkRange(
      bus::get<double>(node, w, "horizontal_alert_limit_m", i.horizontal_alert_limit_m), 0.01, 1e7,
      "integrity.horizontal_alert_limit_m");
  i.vertical_alert_limit_m =
      bus::checkRange(bus::get<double>(node, w, "vertical_alert_limit_m", i.vertical_alert_limit_m),
                      0.01, 1e7, "integrity.vertical_alert_limit_m");
  const YAML::Node d = node ? node["detector"] : YAML::Node();
  bus::checkKeys(d, w + ".detector",
                 {"window_epochs", "threshold", "ambiguity_margin", "ambiguity_correlation",
                  "rank_tolerance", "hypotheses"});
  bus::parseGlrStatistics(d, w + ".detector", i.detector);
  if (i.enabled && e.aiding != core::AidingMode::kTightlyCoupled)
    throw bus::ConfigError(
        "configuration integrity.enabled: true needs mode: tightly_coupled (the protection "
        "levels come from the GLR on pseudoranges)");
}
}  // namespace

FilterConfig parseFilterConfig(const YAML::Node& root) {
  FilterConfig c;
  bus::checkKeys(root, "",
                 {"vehicle_id",
                  "solution_rate_hz",
                  "sequencer_max_wait_s",
                  "recovery",
                  "solution_writer_profile",
                  "initial_state",
                  "inputs",
                  "mode",
                  "fusion",
                  "star_tracker_updates",
                  "ekf",
                  "failed_axis",
                  "adaptive",
                  "federated",
                  "multi_dimensional",
                  "command_issuers",
                  "issuer_identities",
                  "time_jump",
                  "fault_monitor",
                  "alignment",
                  "integrity",
                  "low_latency_output"},
                 bus::kParticipantKeys);
  core::EngineConfig& e = c.engine;
  c.vehicle_id = bus::get<std::uint32_t>(root, "", "vehicle_id", 1);
  const double rate = bus::checkRange(bus::get<double>(root, "", "solution_rate_hz", 10.0), 1.0,
                                      1000.0, "solution_rate_hz");
  e.solution_period_ns = seconds(1.0 / rate);
  c.sequencer_max_wait_ns =
      seconds(bus::checkRange(bus::get<double>(root, "", "sequencer_max_wait_s", 0.5), 0.001, 60.0,
                              "sequencer_max_wait_s"));

  const YAML::Node low = root["low_latency_output"];
  bus::checkKeys(low, "low_latency_output", {"enabled", "max_buffered_increments"});
  c.low_latency_output = bus::get<bool>(low, "low_latency_output", "enabled", false);
  c.low_latency_max_buffered = static_cast<std::size_t>(
      bus::checkRange(bus::get<double>(low, "low_latency_output", "max_buffered_increments", 400),
                      1.0, 100000.0, "low_latency_output.max_buffered_increments"));

  const YAML::Node rec = root["recovery"];
  bus::checkKeys(rec, "recovery",
                 {"history_s", "snapshot_period_s", "exclusion_margin_s",
                  "max_accel_compensation_mg", "max_gyro_compensation_deg_per_h"});
  c.recovery_history_ns = seconds(bus::checkRange(
      bus::get<double>(rec, "recovery", "history_s", 40.0), 0.0, 600.0, "recovery.history_s"));
  c.recovery_snapshot_period_ns =
      seconds(bus::checkRange(bus::get<double>(rec, "recovery", "snapshot_period_s", 1.0), 0.01,
                              60.0, "recovery.snapshot_period_s"));
  c.recovery_onset_margin_ns =
      seconds(bus::checkRange(bus::get<double>(rec, "recovery", "exclusion_margin_s", 5.0), 0.0,
                              60.0, "recovery.exclusion_margin_s"));
  c.max_accel_compensation_mps2 =
      bus::checkRange(bus::get<double>(rec, "recovery", "max_accel_compensation_mg", 50.0), 0.0,
                      1e4, "recovery.max_accel_compensation_mg") *
      units::kMilliG;
  c.max_gyro_compensation_radps =
      bus::checkRange(bus::get<double>(rec, "recovery", "max_gyro_compensation_deg_per_h", 200.0),
                      0.0, 1e6, "recovery.max_gyro_compensation_deg_per_h") *
      units::kDegPerHour;
  c.solution_writer_profile =
      bus::get<std::string>(root, "", "solution_writer_profile", c.solution_writer_profile);
  c.command_issuers =
      bus::get<std::vector<std::string>>(root, "", "command_issuers", c.command_issuers);
  const YAML::Node jump = root["time_jump"];
  bus::checkKeys(jump, "time_jump", {"tolerance_s", "confirmations"});
  c.time_jump.tolerance_ns = static_cast<std::uint64_t>(
      seconds(bus::checkRange(bus::get<double>(jump, "time_jump", "tolerance_s", 2.0), 0.0, 86400.0,
                              "time_jump.tolerance_s")));
  c.time_jump.confirmations = static_cast<int>(bus::checkRange(
      bus::get<int>(jump, "time_jump", "confirmations", 3), 1, 1000, "time_jump.confirmations"));
  for (const std::string& issuer : c.command_issuers) {
    if (issuer.empty() || issuer.size() > 64)
      throw bus::ConfigError("configuration command_issuers: '" + issuer +
                             "' must have 1 to 64 characters (FilterCommand.issuer)");
  }
  c.issuer_identities = bus::get<std::map<std::string, std::string>>(root, "", "issuer_identities",
                                                                     c.issuer_identities);
  for (const std::string& issuer : c.command_issuers)
    c.issuer_identities.emplace(issuer, "navbus-" + issuer);
  if (const YAML::Node fm = root["fault_monitor"]) {
    bus::checkKeys(fm, "fault_monitor", {"participant", "identity", "timeout_s"});
    FaultMonitorWatch w;
    if (auto it = c.issuer_identities.find("fault-manager"); it != c.issuer_identities.end())
      w.identity = it->second;
    w.participant = bus::get<std::string>(fm, "fault_monitor", "participant", w.participant);
    w.identity = bus::get<std::string>(fm, "fault_monitor", "identity", w.identity);
    w.timeout_ns = seconds(bus::checkRange(bus::get<double>(fm, "fault_monitor", "timeout_s", 3.0),
                                           0.1, 3600.0, "fault_monitor.timeout_s"));
    c.fault_monitor = w;
  }
  for (const auto& [issuer, name] : c.issuer_identities) {
    if (std::find(c.command_issuers.begin(), c.command_issuers.end(), issuer) ==
        c.command_issuers.end())
      throw bus::ConfigError("configuration issuer_identities: '" + issuer +
                             "' is not one of command_issuers");
  }
  // No initial_state, or `initial_state: align` (to override an extended file's state): the
  // filter aligns from its inputs.
  const YAML::Node init = root["initial_state"];
  const bool align = !init || (init.IsScalar() && init.Scalar() == "align");
  e.start = align ? core::StartSource::kAligned : core::StartSource::kConfigured;
  if (init && init.IsScalar() && !align) {
    throw bus::ConfigError("configuration initial_state = '" + init.Scalar() +
                           "': expected a state (latitude_deg, ...) or 'align'");
  }
  if (!align) parseInitialState(init, e.initial_state);

  const YAML::Node inputs = root["inputs"];
  if (!inputs) throw bus::ConfigError("configuration inputs is missing");
  bus::checkKeys(inputs, "inputs", {"imu", "gnss_observations", "gnss_fix", "star_tracker"});
  c.imu = *input(inputs, "imu", true);
  e.imu_period_s = 1e-9 * static_cast<double>(c.imu.period_ns);
  c.gnss_observations = input(inputs, "gnss_observations", false);
  c.gnss_fix = input(inputs, "gnss_fix", false);
  c.star_tracker = input(inputs, "star_tracker", false);

  e.aiding = choice<core::AidingMode>(root, "", "mode", "inertial_only",
                                      {{"inertial_only", core::AidingMode::kInertialOnly},
                                       {"tightly_coupled", core::AidingMode::kTightlyCoupled},
                                       {"loosely_coupled", core::AidingMode::kLooselyCoupled},
                                       {"multi_dimensional", core::AidingMode::kMultiDimensional}});
  e.fusion = choice<core::FusionStructure>(root, "", "fusion", "centralized",
                                           {{"centralized", core::FusionStructure::kCentralized},
                                            {"federated", core::FusionStructure::kFederated},
                                            {"adaptive", core::FusionStructure::kAdaptive}});
  e.use_star_tracker = bus::get<bool>(root, "", "star_tracker_updates", false);
  if (e.aiding == core::AidingMode::kTightlyCoupled && !c.gnss_observations) {
    throw bus::ConfigError("configuration mode = tightly_coupled needs inputs.gnss_observations");
  }
  if ((e.aiding == core::AidingMode::kLooselyCoupled ||
       e.aiding == core::AidingMode::kMultiDimensional) &&
      !c.gnss_fix) {
    throw bus::ConfigError(
        "configuration mode = loosely_coupled / multi_dimensional needs "
        "inputs.gnss_fix");
  }
  if (e.start == core::StartSource::kAligned && !c.gnss_fix && !c.gnss_observations) {
    throw bus::ConfigError(
        "configuration has no initial_state, so the filter aligns from its inputs: that needs "
        "inputs.gnss_fix or inputs.gnss_observations for its position");
  }
  if (e.use_star_tracker && !c.star_tracker) {
    throw bus::ConfigError("configuration star_tracker_updates = true needs inputs.star_tracker");
  }
  {
    // Check the structure against the mode once, with the engine's own rule.
    core::EngineConfig probe = e;
    probe.fusion = core::FusionStructure::kCentralized;
    core::NavigationEngine engine(probe);
    if (e.aiding != core::AidingMode::kInertialOnly && !engine.selectFusion(e.fusion)) {
      throw bus::ConfigError(
          "configuration fusion = '" + bus::get<std::string>(root, "", "fusion", "centralized") +
          "' does not apply to mode '" + bus::get<std::string>(root, "", "mode", "") +
          "' (federated needs star_tracker_updates; adaptive needs "
          "loosely_coupled)");
    }
  }

  // EKF parameters, in the units of the papers' error budgets.
  const YAML::Node tc = root["ekf"];
  bus::checkKeys(
      tc, "ekf",
      {"gravity", "accel_noise_ug_per_sqrthz", "gyro_arw_deg_per_sqrth",
       "clock_bias_noise_m_per_sqrts", "clock_drift_noise_mps_per_sqrts",
       "initial_position_sigma_m", "initial_velocity_sigma_mps", "initial_level_sigma_mrad",
       "initial_heading_sigma_mrad", "accel_bias_sigma_ug", "gyro_bias_sigma_deg_per_h",
       "initial_clock_bias_sigma_m", "initial_clock_drift_sigma_mps", "gate_sigma",
       "initial_clock_bias_m", "initial_clock_drift_mps", "star_tracker_bias_sigma_arcsec",
       "star_tracker_bias_correlation_time_s"});
  using units::kArcsec;
  using units::kDeg;
  using units::kMicroG;
  auto& t = e.tuning;
  const std::string w = "ekf";
  t.gravity =
      choice<core::earth::GravityModel>(tc, w, "gravity", "wgs84",
                                        {{"wgs84", core::earth::GravityModel::kWgs84Normal},
                                         {"point_mass", core::earth::GravityModel::kPointMass}});
  t.accel_noise_mps2_per_sqrthz =
      bus::get<double>(tc, w, "accel_noise_ug_per_sqrthz", 10.0) * kMicroG;
  t.gyro_noise_radps_per_sqrthz =
      bus::get<double>(tc, w, "gyro_arw_deg_per_sqrth", 0.001) * kDeg / 60.0;
  t.clock_bias_noise_m_per_sqrts = bus::get<double>(tc, w, "clock_bias_noise_m_per_sqrts", 0.1);
  t.clock_drift_noise_mps_per_sqrts =
      bus::get<double>(tc, w, "clock_drift_noise_mps_per_sqrts", 0.01);
  t.pos_sigma_m = bus::get<double>(tc, w, "initial_position_sigma_m", 40.0);
  t.vel_sigma_mps = bus::get<double>(tc, w, "initial_velocity_sigma_mps", 1.0);
  t.level_sigma_rad = bus::get<double>(tc, w, "initial_level_sigma_mrad", 1.0) * 1e-3;
  t.heading_sigma_rad = bus::get<double>(tc, w, "initial_heading_sigma_mrad", 5.0) * 1e-3;
  t.accel_bias_sigma_mps2 = bus::get<double>(tc, w, "accel_bias_sigma_ug", 1000.0) * kMicroG;
  t.gyro_bias_sigma_radps =
      bus::get<double>(tc, w, "gyro_bias_sigma_deg_per_h", 1.0) * kDeg / 3600.0;
  t.clock_bias_sigma_m = bus::get<double>(tc, w, "initial_clock_bias_sigma_m", 3000.0);
  t.clock_drift_sigma_mps = bus::get<double>(tc, w, "initial_clock_drift_sigma_mps", 1.0);
  t.gate_sigma = bus::get<double>(tc, w, "gate_sigma", 5.0);
  if (t.gate_sigma != 0.0) bus::checkRange(t.gate_sigma, 1.0, 1e3, "ekf.gate_sigma (0: off)");
  for (const auto& [key, value] :
       {std::pair<const char*, double>{"initial_position_sigma_m", t.pos_sigma_m},
        {"initial_velocity_sigma_mps", t.vel_sigma_mps},
        {"initial_level_sigma_mrad", t.level_sigma_rad},
        {"initial_heading_sigma_mrad", t.heading_sigma_rad},
        {"accel_bias_sigma_ug", t.accel_bias_sigma_mps2},
        {"gyro_bias_sigma_deg_per_h", t.gyro_bias_sigma_radps},
        {"initial_clock_bias_sigma_m", t.clock_bias_sigma_m},
        {"initial_clock_drift_sigma_mps", t.clock_drift_sigma_mps}}) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      throw bus::ConfigError("configuration ekf." + std::string(key) +
                             " must be positive and finite (covariance), got " +
                             std::to_string(value));
    }
  }
  // The star tracker's Gauss-Markov bias, modelled as states when its sigma is positive.
  t.star_tracker_bias_sigma_rad =
      bus::checkRange(bus::get<double>(tc, w, "star_tracker_bias_sigma_arcsec",
                                       t.star_tracker_bias_sigma_rad / kArcsec),
                      0.0, 3600.0, "ekf.star_tracker_bias_sigma_arcsec (0: not modelled)") *
      kArcsec;
  t.star_tracker_bias_correlation_time_s =
      bus::checkRange(bus::get<double>(tc, w, "star_tracker_bias_correlation_time_s",
                                       t.star_tracker_bias_correlation_time_s),
                      1.0, 1e7, "ekf.star_tracker_bias_correlation_time_s");
  if (t.star_tracker_bias_sigma_rad > 0.0 && !e.use_star_tracker) {
    throw bus::ConfigError(
        "configuration ekf.star_tracker_bias_sigma_arcsec needs star_tracker_updates = true");
  }
  e.initial_clock_bias_m = bus::get<double>(tc, w, "initial_clock_bias_m", 0.0);
  e.initial_clock_drift_mps = bus::get<double>(tc, w, "initial_clock_drift_mps", 0.0);

  // A failed IMU axis (CMD_FAIL_SENSOR_AXIS): its error is a random-walk bias.
  const YAML::Node fa = root["failed_axis"];
  bus::checkKeys(fa, "failed_axis",
                 {"accel_bias_sigma_mg", "accel_bias_rw_mg_per_sqrts", "gyro_bias_sigma_dps",
                  "gyro_bias_rw_dps_per_sqrts"});
  const std::string wf = "failed_axis";
  auto positive = [](double v, const std::string& key) {
    return bus::checkRange(v, 1e-12, 1e12, "failed_axis." + key);
  };
  t.failed_accel_bias_sigma_mps2 =
      positive(bus::get<double>(fa, wf, "accel_bias_sigma_mg",
                                t.failed_accel_bias_sigma_mps2 / units::kMilliG),
               "accel_bias_sigma_mg") *
      units::kMilliG;
  t.failed_accel_bias_rw_mps2_per_sqrts =
      positive(bus::get<double>(fa, wf, "accel_bias_rw_mg_per_sqrts",
                                t.failed_accel_bias_rw_mps2_per_sqrts / units::kMilliG),
               "accel_bias_rw_mg_per_sqrts") *
      units::kMilliG;
  t.failed_gyro_bias_sigma_radps = positive(bus::get<double>(fa, wf, "gyro_bias_sigma_dps",
                                                             t.failed_gyro_bias_sigma_radps / kDeg),
                                            "gyro_bias_sigma_dps") *
                                   kDeg;
  t.failed_gyro_bias_rw_radps_per_sqrts =
      positive(bus::get<double>(fa, wf, "gyro_bias_rw_dps_per_sqrts",
                                t.failed_gyro_bias_rw_radps_per_sqrts / kDeg),
               "gyro_bias_rw_dps_per_sqrts") *
      kDeg;

  const YAML::Node ad = root["adaptive"];
  bus::checkKeys(ad, "adaptive",
                 {"window", "floor_position_m", "floor_velocity_mps", "floor_attitude_arcsec",
                  "floor_at_reported"});
  bus::checkKeys(root["federated"], "federated", {"share"});
  const std::string wa = "adaptive";
  t.adaptive_window =
      static_cast<int>(bus::checkRange(bus::get<double>(ad, wa, "window", 50), 2,
                                       core::InnovationWindow<3>::kMaxLength, "adaptive.window"));
  t.adaptive_floor_position_m = bus::get<double>(ad, wa, "floor_position_m", 0.3);
  t.adaptive_floor_velocity_mps = bus::get<double>(ad, wa, "floor_velocity_mps", 0.01);
  t.adaptive_floor_attitude_rad = bus::get<double>(ad, wa, "floor_attitude_arcsec", 0.2) * kArcsec;
  t.adaptive_floor_at_reported =
      bus::get<bool>(ad, wa, "floor_at_reported", t.adaptive_floor_at_reported);
  t.federated_share =
      bus::checkRange(bus::get<double>(root["federated"], "federated", "share", 2.0), 1.0, 100.0,
                      "federated.share");

  const YAML::Node md = root["multi_dimensional"];
  bus::checkKeys(md, "multi_dimensional",
                 {"policy", "recovery_s", "gnss_timeout_s", "constraint_rate_hz", "zupt_sigma_mps",
                  "nhc_sigma_mps", "stationary", "unestimated_states", "resets"});
  const std::string wm = "multi_dimensional";
  auto& m = e.mdf;
  m.policy = choice<core::MdfPolicy>(md, wm, "policy", "mdf",
                                     {{"mdf", core::MdfPolicy::kMultiDimensional},
                                      {"continue", core::MdfPolicy::kContinue},
                                      {"reset_all", core::MdfPolicy::kResetAll}});
  m.unestimated = choice<core::ReducedStates>(
      md, wm, "unestimated_states", "consider",
      {{"consider", core::ReducedStates::kConsidered}, {"drop", core::ReducedStates::kDropped}});
  m.reset_form = choice<core::ResetForm>(
      md, wm, "resets", "inflate",
      {{"inflate", core::ResetForm::kInflate}, {"paper", core::ResetForm::kPaper}});
  m.recovery_s = bus::checkRange(bus::get<double>(md, wm, "recovery_s", 5.0), 0.0, 600.0,
                                 "multi_dimensional.recovery_s");
  m.gnss_timeout_s = bus::checkRange(bus::get<double>(md, wm, "gnss_timeout_s", 1.5), 0.01, 600.0,
                                     "multi_dimensional.gnss_timeout_s");
  m.constraint_period_s =
      1.0 / bus::checkRange(bus::get<double>(md, wm, "constraint_rate_hz", 10.0), 0.1, 1000.0,
                            "multi_dimensional.constraint_rate_hz");
  m.zupt_sigma_mps = bus::checkRange(bus::get<double>(md, wm, "zupt_sigma_mps", 0.01), 1e-6, 10.0,
                                     "multi_dimensional.zupt_sigma_mps");
  m.nhc_sigma_mps = bus::checkRange(bus::get<double>(md, wm, "nhc_sigma_mps", 0.1), 1e-6, 10.0,
                                    "multi_dimensional.nhc_sigma_mps");
  const YAML::Node st = md ? md["stationary"] : YAML::Node();
  const std::string ws = "multi_dimensional.stationary";
  bus::checkKeys(st, ws, {"window_s", "accel_std_mps2", "gyro_std_dps", "speed_mps"});
  m.stationarity.window_s =
      bus::checkRange(bus::get<double>(st, ws, "window_s", 1.0), 0.05, 10.0, ws + ".window_s");
  m.stationarity.accel_std_mps2 = bus::get<double>(st, ws, "accel_std_mps2", 0.03);
  m.stationarity.gyro_std_radps = bus::get<double>(st, ws, "gyro_std_dps", 0.3) * kDeg;
  m.stationarity.speed_mps = bus::get<double>(st, ws, "speed_mps", 0.3);
  parseAlignment(root["alignment"], e);
  parseIntegrity(root["integrity"], e);
  return c;
}

}  // namespace navbus::nav_filter
