#include "navbus/nav_filter/filter_config.hpp"

#include <algorithm>
#include <array>
#include <bitset>

#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/key_reader.hpp"
#include "navbus/core/filter/innovation_window.hpp"
#include "navbus/core/ins/velocity_history.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"

namespace navbus::nav_filter {

namespace {
/// File units of the filter's configuration.
constexpr bus::FileUnit kMicroG{[](double v) { return v * units::kMicroG; }};
constexpr bus::FileUnit kMilliG{[](double v) { return v * units::kMilliG; }};
constexpr bus::FileUnit kMilliRad{[](double v) { return v * 1e-3; }};
constexpr bus::FileUnit kPartsPerMillion{[](double v) { return v * units::kPpm; }};
constexpr bus::FileUnit kDegree{[](double v) { return v * units::kDeg; }};
constexpr bus::FileUnit kArcsecond{[](double v) { return v * units::kArcsec; }};
constexpr bus::FileUnit kDegPerHour{[](double v) { return v * units::kDegPerHour; }};
/// The EKF's gyro bias sigma has always converted as v * kDeg / 3600 (bit for bit).
constexpr bus::FileUnit kGyroBiasDegPerHour{[](double v) { return v * units::kDeg / 3600.0; }};
constexpr bus::FileUnit kDegPerSqrtHour{[](double v) { return v * units::kDeg / 60.0; }};
constexpr bus::Range kAnyNonNegative{0.0, 1e300};

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
  if (key == "gnss_fix") {
    bus::checkKeys(n, where, {"id", "period_s", "time_offset_s", "velocity_time_offset_s"});
  } else if (key == "gnss_observations") {
    bus::checkKeys(n, where, {"id", "period_s", "time_offset_s", "second_id"});
  } else {
    bus::checkKeys(n, where, {"id", "period_s", "time_offset_s"});
  }
  InputConfig c;
  c.id = bus::require<std::uint32_t>(n, where, "id");
  c.period_ns = seconds(
      bus::checkRange(bus::require<double>(n, where, "period_s"), 1e-4, 60.0, where + ".period_s"));
  if (n["time_offset_s"])
    c.time_offset_ns = seconds(bus::checkRange(bus::require<double>(n, where, "time_offset_s"),
                                               -10.0, 10.0, where + ".time_offset_s"));
  if (n["velocity_time_offset_s"])
    c.velocity_time_offset_ns =
        seconds(bus::checkRange(bus::require<double>(n, where, "velocity_time_offset_s"), -1.0, 0.0,
                                where + ".velocity_time_offset_s"));
  return c;
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
  core::InitialAlignmentConfig& a = e.alignment;
  const core::FilterTuning& t = e.tuning;
  a.budget.accel_bias_sigma_mps2 = t.accel_bias_sigma_mps2;
  a.budget.gyro_bias_sigma_radps = t.gyro_bias_sigma_radps;
  a.budget.velocity_random_walk_mps_per_sqrts = t.accel_noise_mps2_per_sqrthz;
  a.budget.angle_random_walk_rad_per_sqrts = t.gyro_noise_radps_per_sqrthz;
  a.rest = e.mdf.stationarity;
  a.imu_period_s = e.imu_period_s;
  bus::KeyReader r(node, "alignment");
  r.number("static_window_s", a.static_window_s, {1.0, 3600.0});
  r.number("min_static_window_s", a.min_static_window_s, {0.1, a.static_window_s})
      .number("max_heading_sigma_deg", a.max_heading_sigma_rad, {0.0, 180.0}, kDegree)
      .number("course_min_speed_mps", a.course_min_speed_mps, {0.1, 1e4})
      .number("course_sigma_deg", a.course_sigma_rad, {1e-3, 90.0}, kDegree)
      .number("max_course_heading_sigma_deg", a.max_course_heading_sigma_rad, {0.01, 180.0},
              kDegree)
      .number("course_window_s", a.course_window_s, {0.0, 600.0})
      .number("course_check_heading_sigma_deg", a.course_check_heading_sigma_rad, {0.0, 180.0},
              kDegree)
      .finish();
}

/// Protection levels (tightly coupled): the risks, the alert limits and the GLR the fault
/// manager runs (its statistics keys, as in the fault manager's `glr` block).
void parseIntegrity(const YAML::Node& node, core::EngineConfig& e) {
  core::IntegrityConfig& i = e.integrity;
  i.enabled = static_cast<bool>(node);  // a block present enables it unless it says otherwise
  bus::KeyReader r(node, "integrity");
  r.value("enabled", i.enabled)
      .number("integrity_risk", i.integrity_risk, {1e-15, 0.1})
      .number("missed_detection_probability", i.missed_detection_probability, {1e-12, 0.5})
      .number("horizontal_alert_limit_m", i.horizontal_alert_limit_m, {0.01, 1e7})
      .number("vertical_alert_limit_m", i.vertical_alert_limit_m, {0.01, 1e7})
      .nested({"detector"})
      .finish();
  const YAML::Node d = node ? node["detector"] : YAML::Node();
  bus::checkKeys(d, "integrity.detector",
                 {"window_epochs", "threshold", "ambiguity_margin", "ambiguity_correlation",
                  "rank_tolerance", "hypotheses"});
  bus::parseGlrStatistics(d, "integrity.detector", i.detector);
  if (i.enabled && e.aiding == core::AidingMode::kInertialOnly)
    throw bus::ConfigError(
        "configuration integrity.enabled: true needs GNSS (mode: tightly_coupled, "
        "loosely_coupled or multi_dimensional): the protection levels come from the GLR on its "
        "measurements");
  if (i.enabled && e.aiding != core::AidingMode::kTightlyCoupled &&
      e.fusion != core::FusionStructure::kCentralized)
    throw bus::ConfigError(
        "configuration integrity.enabled: true on GNSS fixes needs fusion: centralized (the "
        "detector follows the one filter's gain)");
}
/// The filter's test of its own innovations (core/integrity/consistency_monitor.hpp).
void parseConsistency(const YAML::Node& node, core::ConsistencyConfig& k) {
  bus::KeyReader r(node, "consistency");
  r.value("enabled", k.enabled)
      .integer("window_epochs", k.window_epochs,
               {1.0, static_cast<double>(core::ConsistencyMonitor::kMaxWindow)})
      .number("false_alarm_probability", k.false_alarm_probability, {1e-15, 0.5})
      .number("reinitialise_after_s", k.reinitialise_after_s, {0.0, 86400.0})
      .value("inflate_imu_biases_on_alarm", k.inflate_imu_biases_on_alarm)
      .finish();
}
/// A list of names out of `names` (e.g. adaptive_noise.streams) as the set of their indexes.
template <std::size_t N>
std::bitset<N> parseNameList(const YAML::Node& list, const std::string& key,
                             const std::array<const char*, N>& names) {
  if (!list.IsSequence())
    throw bus::ConfigError("configuration " + key + " must be a list of names");
  std::bitset<N> set;
  for (const YAML::Node& item : list) {
    if (!item.IsScalar())
      throw bus::ConfigError("configuration " + key + ": every item must be a name");
    const std::string name = item.Scalar();
    const auto found =
        std::find_if(names.begin(), names.end(), [&](const char* n) { return name == n; });
    if (found == names.end())
      throw bus::ConfigError(fmt::format("configuration {}: '{}' is not one of {}", key, name,
                                         fmt::join(names, " | ")));
    set.set(static_cast<std::size_t>(found - names.begin()));
  }
  return set;
}

std::array<const char*, core::kNoiseStreams> noiseStreamNames() {
  std::array<const char*, core::kNoiseStreams> names{};
  for (int i = 0; i < core::kNoiseStreams; ++i)
    names[static_cast<std::size_t>(i)] = core::noiseStreamName(static_cast<core::NoiseStream>(i));
  return names;
}

/// Bounded adaptive measurement noise (core/filter/adaptive_noise_scale.hpp). The adaptive
/// fusion structure adapts R its own way (seed 001): the two together are refused.
void parseAdaptiveNoise(const YAML::Node& node, core::EngineConfig& e) {
  core::NoiseScaleConfig& n = e.adaptive_noise;
  bus::KeyReader r(node, "adaptive_noise");
  r.value("enabled", n.enabled)
      .integer("window_epochs", n.window_epochs,
               {1.0, static_cast<double>(core::NoiseScaleEstimator::kMaxWindow)})
      .number("floor", n.floor, {1e-3, 1e6})
      .number("ceiling", n.ceiling, {1e-3, 1e6})
      .finish({"streams"});
  if (node && node["streams"])
    e.adaptive_noise_streams =
        parseNameList(node["streams"], "adaptive_noise.streams", noiseStreamNames());
  if (n.ceiling < n.floor)
    throw bus::ConfigError(
        fmt::format("configuration adaptive_noise.ceiling: {} is below adaptive_noise.floor: {}",
                    n.ceiling, n.floor));
  if (n.enabled && e.fusion == core::FusionStructure::kAdaptive)
    throw bus::ConfigError(
        "configuration adaptive_noise.enabled: true with fusion: adaptive (the adaptive "
        "structure estimates R itself; use one or the other)");
}

/// Bounded adaptive process noise (core/filter/adaptive_process_noise.hpp): the centralized
/// filter's inertial Q.
void parseAdaptiveProcessNoise(const YAML::Node& node, core::EngineConfig& e) {
  core::ProcessNoiseScaleConfig& n = e.adaptive_process_noise;
  bus::KeyReader r(node, "adaptive_process_noise");
  r.value("enabled", n.enabled)
      .number("memory_s", n.memory_s, {1.0, 1e6})
      .number("prior_rows", n.prior_rows, {1e-3, 1e6})
      .number("floor", n.floor, {1e-3, 1e6})
      .number("ceiling", n.ceiling, {1e-3, 1e6})
      .finish();
  if (n.ceiling < n.floor)
    throw bus::ConfigError(fmt::format(
        "configuration adaptive_process_noise.ceiling: {} is below adaptive_process_noise.floor: "
        "{}",
        n.ceiling, n.floor));
  if (n.enabled && e.fusion != core::FusionStructure::kCentralized)
    throw bus::ConfigError(fmt::format(
        "configuration adaptive_process_noise.enabled: true with fusion: {} (the process noise "
        "adapts in the centralized filter only)",
        e.fusion == core::FusionStructure::kFederated ? "federated" : "adaptive"));
  if (n.enabled && e.aiding == core::AidingMode::kInertialOnly)
    throw bus::ConfigError(
        "configuration adaptive_process_noise.enabled: true with mode: inertial_only (no "
        "innovations to adapt from)");
}
}  // namespace

namespace {

void parseLowLatency(const YAML::Node& node, FilterConfig& c) {
  bus::KeyReader r(node, "low_latency_output");
  r.value("enabled", c.low_latency_output)
      .integer("max_buffered_increments", c.low_latency_max_buffered, {1.0, 100000.0})
      .finish();
}

void parseRecovery(const YAML::Node& node, FilterConfig& c) {
  bus::KeyReader r(node, "recovery");
  r.seconds("history_s", c.recovery_history_ns, {0.0, 600.0})
      .seconds("snapshot_period_s", c.recovery_snapshot_period_ns, {0.01, 60.0})
      .seconds("exclusion_margin_s", c.recovery_onset_margin_ns, {0.0, 60.0})
      .number("max_accel_compensation_mg", c.max_accel_compensation_mps2, {0.0, 1e4}, kMilliG)
      .number("max_gyro_compensation_deg_per_h", c.max_gyro_compensation_radps, {0.0, 1e6},
              kDegPerHour)
      .number("gap_max_bridged_s", c.engine.gap.max_bridged_s, {0.0, 3600.0})
      .number("gap_accel_sigma_mps2", c.engine.gap.accel_sigma_mps2, {0.0, 1000.0})
      .number("gap_rate_sigma_deg_per_s", c.engine.gap.rate_sigma_radps, {0.0, 1000.0}, kDegree)
      .finish();
}

void parseTimeJump(const YAML::Node& node, bus::TimeJumpRule& rule) {
  bus::KeyReader r(node, "time_jump");
  std::int64_t tolerance_ns = static_cast<std::int64_t>(rule.tolerance_ns);
  r.seconds("tolerance_s", tolerance_ns, {0.0, 86400.0})
      .integer("confirmations", rule.confirmations, {1.0, 1000.0})
      .finish();
  rule.tolerance_ns = static_cast<std::uint64_t>(tolerance_ns);
}

/// Who may command the filter, who they must be under DDS Security, and whose health reports
/// show that faults are monitored.
void parseAuthorities(const YAML::Node& root, FilterConfig& c) {
  for (const std::string& issuer : c.command_issuers) {
    if (issuer.empty() || issuer.size() > 64)
      throw bus::ConfigError("configuration command_issuers: '" + issuer +
                             "' must have 1 to 64 characters (FilterCommand.issuer)");
  }
  for (const std::string& issuer : c.command_issuers)
    c.issuer_identities.emplace(issuer, "navbus-" + issuer);
  if (const YAML::Node fm = root["fault_monitor"]) {
    FaultMonitorWatch w;
    if (auto it = c.issuer_identities.find("fault-manager"); it != c.issuer_identities.end())
      w.identity = it->second;
    bus::KeyReader r(fm, "fault_monitor");
    r.value("participant", w.participant)
        .value("identity", w.identity)
        .seconds("timeout_s", w.timeout_ns, {0.1, 3600.0})
        .seconds("judgement_wait_s", w.judgement_wait_ns, {0.001, 3600.0})
        .value("judged_from_start", w.judged_from_start)
        .value("receivers_judged", w.receivers_judged)
        .finish();
    c.fault_monitor = w;
  }
  for (const auto& [issuer, name] : c.issuer_identities) {
    if (std::find(c.command_issuers.begin(), c.command_issuers.end(), issuer) ==
        c.command_issuers.end())
      throw bus::ConfigError("configuration issuer_identities: '" + issuer +
                             "' is not one of command_issuers");
  }
}

/// No initial_state, or `initial_state: align` (to override an extended file's state): the
/// filter aligns from its inputs.
void parseStart(const YAML::Node& init, core::EngineConfig& e) {
  const bool align = !init || (init.IsScalar() && init.Scalar() == "align");
  e.start = align ? core::StartSource::kAligned : core::StartSource::kConfigured;
  if (init && init.IsScalar() && !align) {
    throw bus::ConfigError("configuration initial_state = '" + init.Scalar() +
                           "': expected a state (latitude_deg, ...) or 'align'");
  }
  if (!align) parseInitialState(init, e.initial_state);
}

void parseInputs(const YAML::Node& inputs, FilterConfig& c) {
  if (!inputs) throw bus::ConfigError("configuration inputs is missing");
  bus::checkKeys(inputs, "inputs", {"imu", "gnss_observations", "gnss_fix", "star_tracker"});
  c.imu = *input(inputs, "imu", true);
  c.engine.imu_period_s = 1e-9 * static_cast<double>(c.imu.period_ns);
  c.gnss_observations = input(inputs, "gnss_observations", false);
  if (c.gnss_observations && inputs["gnss_observations"]["second_id"]) {
    const auto second = bus::require<std::uint32_t>(inputs["gnss_observations"],
                                                    "inputs.gnss_observations", "second_id");
    if (second == c.gnss_observations->id)
      throw bus::ConfigError("configuration inputs.gnss_observations.second_id = " +
                             std::to_string(second) + " is the first receiver's id as well");
    c.second_gnss_receiver_id = second;
    c.engine.fused_receivers = 2;
  }
  c.gnss_fix = input(inputs, "gnss_fix", false);
  // The engine brings a lagging fix velocity forward through its velocity history.
  const std::int64_t reach_ns = (core::VelocityHistory::kLength - 2) * c.imu.period_ns;
  if (c.gnss_fix && -c.gnss_fix->velocity_time_offset_ns > reach_ns)
    throw bus::ConfigError(
        "configuration inputs.gnss_fix.velocity_time_offset_s " +
        std::to_string(1e-9 * static_cast<double>(c.gnss_fix->velocity_time_offset_ns)) +
        " reaches further back than the velocity history (" +
        std::to_string(core::VelocityHistory::kLength - 2) + " IMU periods, " +
        std::to_string(1e-9 * static_cast<double>(reach_ns)) + " s)");
  c.star_tracker = input(inputs, "star_tracker", false);
}

/// What the mode and fusion structure need of the inputs, checked with the engine's own rule.
void checkModeAgainstInputs(const YAML::Node& root, const FilterConfig& c) {
  const core::EngineConfig& e = c.engine;
  if (e.aiding == core::AidingMode::kTightlyCoupled && !c.gnss_observations) {
    throw bus::ConfigError("configuration mode = tightly_coupled needs inputs.gnss_observations");
  }
  if (c.second_gnss_receiver_id && e.aiding != core::AidingMode::kTightlyCoupled) {
    throw bus::ConfigError(
        "configuration inputs.gnss_observations.second_id = " +
        std::to_string(*c.second_gnss_receiver_id) +
        " needs mode = tightly_coupled (a second receiver's pseudoranges are fused only there)");
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

/// The fix's position error states: only where fixes are fused, with both sigmas given.
void checkFixPositionError(const core::EngineConfig& e) {
  const core::FilterTuning& t = e.tuning;
  if (!(t.fix_position_error_sigma_h_m > 0.0)) {
    if (t.fix_position_error_sigma_v_m > 0.0)
      throw bus::ConfigError(fmt::format(
          "configuration ekf.fix_position_error_sigma_v_m ({} m) needs "
          "ekf.fix_position_error_sigma_h_m > 0 (the horizontal sigma turns the states on)",
          t.fix_position_error_sigma_v_m));
    return;
  }
  if (e.aiding != core::AidingMode::kLooselyCoupled &&
      e.aiding != core::AidingMode::kMultiDimensional)
    throw bus::ConfigError(fmt::format(
        "configuration ekf.fix_position_error_sigma_h_m ({} m) needs mode: loosely_coupled or "
        "multi_dimensional (fixes are fused only there)",
        t.fix_position_error_sigma_h_m));
  if (!(t.fix_position_error_sigma_v_m > 0.0))
    throw bus::ConfigError(
        fmt::format("configuration ekf.fix_position_error_sigma_v_m ({} m) must be positive with "
                    "ekf.fix_position_error_sigma_h_m ({} m)",
                    t.fix_position_error_sigma_v_m, t.fix_position_error_sigma_h_m));
}

/// EKF parameters, in the units of the papers' error budgets.
void parseEkf(const YAML::Node& node, core::EngineConfig& e) {
  core::FilterTuning& t = e.tuning;
  bus::KeyReader r(node, "ekf");
  r.choice("gravity", t.gravity,
           {{"wgs84", core::earth::GravityModel::kWgs84Normal},
            {"point_mass", core::earth::GravityModel::kPointMass}})
      .number("accel_noise_ug_per_sqrthz", t.accel_noise_mps2_per_sqrthz, kAnyNonNegative, kMicroG)
      .number("gyro_arw_deg_per_sqrth", t.gyro_noise_radps_per_sqrthz, kAnyNonNegative,
              kDegPerSqrtHour)
      .number("clock_bias_noise_m_per_sqrts", t.clock_bias_noise_m_per_sqrts, kAnyNonNegative)
      .number("clock_drift_noise_mps_per_sqrts", t.clock_drift_noise_mps_per_sqrts, kAnyNonNegative)
      .number("accel_bias_rw_ug_per_sqrts", t.accel_bias_rw_mps2_per_sqrts, kAnyNonNegative,
              kMicroG)
      .number("gyro_bias_rw_dps_per_sqrts", t.gyro_bias_rw_radps_per_sqrts, kAnyNonNegative,
              kDegree)
      .number("initial_position_sigma_m", t.pos_sigma_m, kAnyNonNegative)
      .number("initial_velocity_sigma_mps", t.vel_sigma_mps, kAnyNonNegative)
      .number("initial_level_sigma_mrad", t.level_sigma_rad, kAnyNonNegative, kMilliRad)
      .number("initial_heading_sigma_mrad", t.heading_sigma_rad, kAnyNonNegative, kMilliRad)
      .number("accel_bias_sigma_ug", t.accel_bias_sigma_mps2, kAnyNonNegative, kMicroG)
      .number("gyro_bias_sigma_deg_per_h", t.gyro_bias_sigma_radps, kAnyNonNegative,
              kGyroBiasDegPerHour)
      .number("initial_clock_bias_sigma_m", t.clock_bias_sigma_m, kAnyNonNegative)
      .number("initial_clock_drift_sigma_mps", t.clock_drift_sigma_mps, kAnyNonNegative)
      .number("gate_sigma", t.gate_sigma, kAnyNonNegative)
      // The covariance propagated over up to this interval at once (0: every increment).
      .number("covariance_period_s", t.covariance_period_s, {0.0, 1.0})
      // The IMU's scale-factor errors, states when their sigma is positive.
      .number("accel_scale_factor_sigma_ppm", t.accel_scale_sigma, {0.0, 1e5}, kPartsPerMillion)
      .number("gyro_scale_factor_sigma_ppm", t.gyro_scale_sigma, {0.0, 1e5}, kPartsPerMillion)
      // The star tracker's Gauss-Markov bias, modelled as states when its sigma is positive.
      .number("star_tracker_bias_sigma_arcsec", t.star_tracker_bias_sigma_rad, {0.0, 3600.0},
              kArcsecond)
      .number("star_tracker_bias_correlation_time_s", t.star_tracker_bias_correlation_time_s,
              {1.0, 1e7})
      // A land vehicle's residual mounting misalignment, states when its sigma is positive.
      .number("mounting_misalignment_sigma_deg", t.mounting_misalignment_sigma_rad, {0.0, 30.0},
              kDegree)
      .number("mounting_misalignment_rw_deg_per_sqrts", t.mounting_misalignment_rw_rad_per_sqrts,
              {0.0, 1.0}, kDegree)
      // Each satellite's time-correlated pseudorange error, states when its sigma is positive.
      .number("pseudorange_error_sigma_m", t.pseudorange_error_sigma_m, {0.0, 1000.0})
      .number("pseudorange_error_correlation_time_s", t.pseudorange_error_correlation_time_s,
              {1.0, 1e7})
      // The fix's time-correlated position error (loose coupling), states when its sigma is
      // positive.
      .number("fix_position_error_sigma_h_m", t.fix_position_error_sigma_h_m, {0.0, 1000.0})
      .number("fix_position_error_sigma_v_m", t.fix_position_error_sigma_v_m, {0.0, 1000.0})
      .number("fix_position_error_correlation_time_s", t.fix_position_error_correlation_time_s,
              {1.0, 1e7})
      .number("initial_clock_bias_m", e.initial_clock_bias_m, {-1e9, 1e9})
      .number("initial_clock_drift_mps", e.initial_clock_drift_mps, {-1e6, 1e6})
      .finish();
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
    if (!(value > 0.0)) {
      throw bus::ConfigError("configuration ekf." + std::string(key) +
                             " must be positive (covariance), got " + std::to_string(value));
    }
  }
  if (t.star_tracker_bias_sigma_rad > 0.0 && !e.use_star_tracker) {
    throw bus::ConfigError(
        "configuration ekf.star_tracker_bias_sigma_arcsec needs star_tracker_updates = true");
  }
  if (t.mounting_misalignment_sigma_rad > 0.0 && e.aiding != core::AidingMode::kMultiDimensional) {
    throw bus::ConfigError(fmt::format(
        "configuration ekf.mounting_misalignment_sigma_deg ({} deg) needs mode: "
        "multi_dimensional (the non-holonomic constraint that sees it is fused only there)",
        t.mounting_misalignment_sigma_rad / units::kDeg));
  }
  if (t.pseudorange_error_sigma_m > 0.0 && e.aiding != core::AidingMode::kTightlyCoupled) {
    throw bus::ConfigError("configuration ekf.pseudorange_error_sigma_m (" +
                           std::to_string(t.pseudorange_error_sigma_m) +
                           " m) needs mode: tightly_coupled (pseudoranges are fused only there)");
  }
  checkFixPositionError(e);
}

/// A failed IMU axis (CMD_FAIL_SENSOR_AXIS): its error is a random-walk bias.
void parseFailedAxis(const YAML::Node& node, core::FilterTuning& t) {
  constexpr bus::Range kPositive{1e-12, 1e12};
  bus::KeyReader r(node, "failed_axis");
  r.number("accel_bias_sigma_mg", t.failed_accel_bias_sigma_mps2, kPositive, kMilliG)
      .number("accel_bias_rw_mg_per_sqrts", t.failed_accel_bias_rw_mps2_per_sqrts, kPositive,
              kMilliG)
      .number("gyro_bias_sigma_dps", t.failed_gyro_bias_sigma_radps, kPositive, kDegree)
      .number("gyro_bias_rw_dps_per_sqrts", t.failed_gyro_bias_rw_radps_per_sqrts, kPositive,
              kDegree)
      .finish();
}

/// The adaptive (seed 001 eqs. 30-34) and federated structures.
void parseFusionTuning(const YAML::Node& root, core::FilterTuning& t) {
  bus::KeyReader adaptive(root["adaptive"], "adaptive");
  adaptive
      .integer("window", t.adaptive_window,
               {2.0, static_cast<double>(core::InnovationWindow<3>::kMaxLength)})
      .number("floor_position_m", t.adaptive_floor_position_m, kAnyNonNegative)
      .number("floor_velocity_mps", t.adaptive_floor_velocity_mps, kAnyNonNegative)
      .number("floor_attitude_arcsec", t.adaptive_floor_attitude_rad, kAnyNonNegative, kArcsecond)
      .value("floor_at_reported", t.adaptive_floor_at_reported)
      .finish();
  bus::KeyReader federated(root["federated"], "federated");
  federated.number("share", t.federated_share, {1.0, 100.0}).finish();
}

/// The multi-dimensional switching filter (seed 004) and its stationarity detector.
void parseMultiDimensional(const YAML::Node& node, core::MdfConfig& m) {
  bus::KeyReader r(node, "multi_dimensional");
  r.choice("policy", m.policy,
           {{"mdf", core::MdfPolicy::kMultiDimensional},
            {"continue", core::MdfPolicy::kContinue},
            {"reset_all", core::MdfPolicy::kResetAll}})
      .choice("unestimated_states", m.unestimated,
              {{"consider", core::ReducedStates::kConsidered},
               {"drop", core::ReducedStates::kDropped},
               {"none", core::ReducedStates::kNone}})
      .choice("resets", m.reset_form,
              {{"inflate", core::ResetForm::kInflate}, {"paper", core::ResetForm::kPaper}})
      .number("recovery_s", m.recovery_s, {0.0, 600.0})
      .number("gnss_timeout_s", m.gnss_timeout_s, {0.01, 600.0})
      .rateHz("constraint_rate_hz", m.constraint_period_s, {0.1, 1000.0})
      .number("zupt_sigma_mps", m.zupt_sigma_mps, {1e-6, 10.0})
      .number("nhc_sigma_mps", m.nhc_sigma_mps, {1e-6, 10.0})
      .number("nhc_velocity_pitch_per_accel_deg_per_mps2",
              m.nhc_velocity_pitch_per_accel_rad_per_mps2, {-10.0, 10.0}, kDegree)
      .value("nhc_with_gnss", m.nhc_with_gnss)
      .nested({"stationary"})
      .finish({"reset_states"});
  if (node && node["reset_states"])
    m.reset_blocks = parseNameList(node["reset_states"], "multi_dimensional.reset_states",
                                   core::kResetBlockNames);
  bus::KeyReader st(node ? node["stationary"] : YAML::Node(), "multi_dimensional.stationary");
  st.number("window_s", m.stationarity.window_s, {0.05, 10.0})
      .number("accel_std_mps2", m.stationarity.accel_std_mps2, kAnyNonNegative)
      .number("gyro_std_dps", m.stationarity.gyro_std_radps, kAnyNonNegative, kDegree)
      .number("speed_mps", m.stationarity.speed_mps, kAnyNonNegative)
      .finish();
}
/// The vehicle's geometry: how the IMU sits in the body, where the GNSS antenna is.
void parseGeometry(const YAML::Node& node, FilterConfig& c) {
  bus::KeyReader r(node, "geometry");
  r.nested({"imu_mounting_rpy_deg", "antenna_lever_arm_b_m", "second_antenna_lever_arm_b_m"})
      .finish();
  if (!node) return;
  const Eigen::Vector3d rpy = bus::getVector3(node, "geometry", "imu_mounting_rpy_deg", 1.0);
  for (int i = 0; i < 3; ++i)
    bus::checkRange(rpy[i], -360.0, 360.0, "geometry.imu_mounting_rpy_deg");
  c.imu_mounting = core::ImuMounting::fromRollPitchYaw(rpy * units::kDeg);
  const Eigen::Vector3d lever = bus::getVector3(node, "geometry", "antenna_lever_arm_b_m", 1.0);
  for (int i = 0; i < 3; ++i)
    bus::checkRange(lever[i], -100.0, 100.0, "geometry.antenna_lever_arm_b_m");
  c.engine.antenna_lever_arm_b_m = lever;
  const Eigen::Vector3d second =
      bus::getVector3(node, "geometry", "second_antenna_lever_arm_b_m", 1.0);
  for (int i = 0; i < 3; ++i)
    bus::checkRange(second[i], -100.0, 100.0, "geometry.second_antenna_lever_arm_b_m");
  c.engine.second_antenna_lever_arm_b_m = second;
}
/// The lane on the least-squares combination of the units (LanesConfig::least_squares_lane_id).
void parseLeastSquaresLane(const YAML::Node& node, LanesConfig& l) {
  if (!node) return;
  std::uint32_t lane_id = 0;
  bool preferred = false;
  bus::KeyReader(node, "lanes.least_squares")
      .value("lane_id", lane_id)
      .value("preferred", preferred)
      .integer("alignment_depth", l.least_squares_alignment_depth, {1, 10000000})
      .finish();
  if (!node["lane_id"])
    throw bus::ConfigError("configuration lanes.least_squares.lane_id is missing");
  if (lane_id == 0)
    throw bus::ConfigError(
        "configuration lanes.least_squares.lane_id 0: 0 names the filter's own IMU in commands");
  l.least_squares_lane_id = lane_id;
  l.least_squares_preferred = preferred;
}

/// Redundant IMUs: one lane per unit (LanesConfig).
void parseLanes(const YAML::Node& node, FilterConfig& c) {
  bus::KeyReader r(node, "lanes");
  LanesConfig& l = c.lanes;
  r.number("switch_ratio", l.selector.switch_ratio, {0.01, 1.0})
      .integer("confirm_epochs", l.selector.confirm_epochs, {1, 100000})
      .integer("max_pending", l.max_pending, {1, 1000000})
      .nested({"units", "evidence", "least_squares"})
      .finish();
  if (!node) return;
  parseLeastSquaresLane(node["least_squares"], l);
  bus::KeyReader(node["evidence"], "lanes.evidence")
      .number("false_decision_probability", l.evidence.false_decision_probability, {1e-15, 0.1})
      .number("max_wait_s", l.evidence.max_wait_s, {1.0, 3600.0})
      .finish();
  const YAML::Node list = node["units"];
  if (!list || !list.IsSequence() || list.size() < 2)
    throw bus::ConfigError("configuration lanes.units must list two or more IMUs");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string w = "lanes.units[" + std::to_string(i) + "]";
    bus::KeyReader u(list[i], w);
    LaneUnit unit;
    u.value("sensor_id", unit.sensor_id).nested({"mounting_rpy_deg", "lever_arm_b_m"}).finish();
    if (!list[i]["sensor_id"])
      throw bus::ConfigError("configuration " + w + ".sensor_id is missing");
    for (const LaneUnit& known : l.units)
      if (known.sensor_id == unit.sensor_id)
        throw bus::ConfigError(
            fmt::format("configuration {}.sensor_id {} is given twice", w, unit.sensor_id));
    const Eigen::Vector3d rpy = bus::getVector3(list[i], w, "mounting_rpy_deg", 1.0);
    for (int k = 0; k < 3; ++k) bus::checkRange(rpy[k], -360.0, 360.0, w + ".mounting_rpy_deg");
    unit.c_b_u = core::dcmFromEuler(rpy * units::kDeg);
    unit.lever_arm_b_m = bus::getVector3(list[i], w, "lever_arm_b_m", 1.0);
    for (int k = 0; k < 3; ++k)
      bus::checkRange(unit.lever_arm_b_m[k], -100.0, 100.0, w + ".lever_arm_b_m");
    l.units.push_back(unit);
  }
  if (l.units.front().sensor_id != c.imu.id)
    throw bus::ConfigError(fmt::format(
        "configuration lanes.units[0].sensor_id {} must be inputs.imu's id {} (the first lane is "
        "the filter's own IMU: its diagnostics feed the fault manager's GLR)",
        l.units.front().sensor_id, c.imu.id));
  if (l.least_squares_lane_id) {
    for (const LaneUnit& u : l.units)
      if (u.sensor_id == *l.least_squares_lane_id)
        throw bus::ConfigError(fmt::format(
            "configuration lanes.least_squares.lane_id {} is a unit's sensor_id (lanes.units): "
            "the combination's lane needs an id of its own",
            *l.least_squares_lane_id));
  }
}

}  // namespace

FilterConfig parseFilterConfig(const YAML::Node& root) {
  FilterConfig c;
  core::EngineConfig& e = c.engine;
  bus::KeyReader top(root, "");
  top.value("vehicle_id", c.vehicle_id)
      .rateHz("solution_rate_hz", e.solution_period_ns, {1.0, 1000.0})
      .seconds("sequencer_max_wait_s", c.sequencer_max_wait_ns, {0.001, 60.0})
      .seconds("sequencer_reserve_s", c.sequencer_reserve_ns, {0.0, 60.0})
      .value("solution_writer_profile", c.solution_writer_profile)
      .value("diagnostics_writer_profile", c.diagnostics_writer_profile)
      .value("command_issuers", c.command_issuers)
      .value("issuer_identities", c.issuer_identities)
      .choice("mode", e.aiding,
              {{"inertial_only", core::AidingMode::kInertialOnly},
               {"tightly_coupled", core::AidingMode::kTightlyCoupled},
               {"loosely_coupled", core::AidingMode::kLooselyCoupled},
               {"multi_dimensional", core::AidingMode::kMultiDimensional}})
      .choice("fusion", e.fusion,
              {{"centralized", core::FusionStructure::kCentralized},
               {"federated", core::FusionStructure::kFederated},
               {"adaptive", core::FusionStructure::kAdaptive}})
      .value("star_tracker_updates", e.use_star_tracker)
      .nested({"low_latency_output", "recovery", "time_jump", "fault_monitor", "initial_state",
               "inputs", "ekf", "failed_axis", "adaptive", "federated", "multi_dimensional",
               "alignment", "integrity", "consistency", "adaptive_noise", "adaptive_process_noise",
               "geometry", "lanes"})
      .finish(bus::kParticipantKeys);
  parseLowLatency(root["low_latency_output"], c);
  parseRecovery(root["recovery"], c);
  parseTimeJump(root["time_jump"], c.time_jump);
  parseAuthorities(root, c);
  parseStart(root["initial_state"], e);
  parseInputs(root["inputs"], c);
  checkModeAgainstInputs(root, c);
  if (c.fault_monitor && c.fault_monitor->receivers_judged && !c.gnss_observations)
    throw bus::ConfigError(
        "configuration fault_monitor.receivers_judged = true needs inputs.gnss_observations (the "
        "epoch after one is held for the receivers' judgement)");
  parseEkf(root["ekf"], e);
  parseFailedAxis(root["failed_axis"], e.tuning);
  parseFusionTuning(root, e.tuning);
  parseMultiDimensional(root["multi_dimensional"], e.mdf);
  parseAlignment(root["alignment"], e);
  parseIntegrity(root["integrity"], e);
  parseConsistency(root["consistency"], e.consistency);
  parseAdaptiveNoise(root["adaptive_noise"], e);
  parseAdaptiveProcessNoise(root["adaptive_process_noise"], e);
  parseGeometry(root["geometry"], c);
  parseLanes(root["lanes"], c);
  return c;
}

}  // namespace navbus::nav_filter
