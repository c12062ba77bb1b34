#include "navbus/fault_manager/fault_config.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "navbus/bus/config.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"

namespace navbus::fault_manager {

namespace {

using units::kDeg;
using units::kMicroG;
using units::kMilliG;

using bus::checkKeys;

/// A [low, high] pair in Hz.
void band(const YAML::Node& node, const std::string& where, double& low, double& high) {
  const YAML::Node b = node ? node["band_hz"] : YAML::Node();
  if (!b) return;
  if (!b.IsSequence() || b.size() != 2)
    throw bus::ConfigError("configuration " + where + ".band_hz must be [low, high] in Hz");
  low = bus::checkRange(bus::as<double>(b[0], where + ".band_hz[0]"), 0.0, 1e6,
                        where + ".band_hz[0]");
  high = bus::checkRange(bus::as<double>(b[1], where + ".band_hz[1]"), low + 1e-3, 1e6,
                         where + ".band_hz[1]");
}

void parseDither(const YAML::Node& n, DitherDetectorConfig& d) {
  const std::string w = "dither";
  checkKeys(n, w,
            {"enabled", "imu_id", "sample_rate_hz", "frequencies_hz", "tolerance_hz",
             "window_samples", "hop_samples", "windows_to_fail", "windows_to_clear",
             "accelerometer", "gyro", "stillness", "actions"});
  core::DitherMonitorConfig& m = d.monitor;
  d.enabled = bus::get<bool>(n, w, "enabled", d.enabled);
  d.imu_id = bus::get<std::uint32_t>(n, w, "imu_id", d.imu_id);
  m.sample_rate_hz = bus::checkRange(bus::get<double>(n, w, "sample_rate_hz", m.sample_rate_hz),
                                     1.0, 1e6, "dither.sample_rate_hz");
  if (n && n["frequencies_hz"]) {
    const YAML::Node f = n["frequencies_hz"];
    if (!f.IsSequence() || f.size() != 3)
      throw bus::ConfigError("configuration dither.frequencies_hz must be [x, y, z] in Hz");
    for (std::size_t i = 0; i < 3; ++i) {
      const std::string path = "dither.frequencies_hz[" + std::to_string(i) + "]";
      m.dither_frequency_hz[i] =
          bus::checkRange(bus::as<double>(f[i], path), 1.0, m.sample_rate_hz / 2, path);
    }
  }
  m.tolerance_hz = bus::checkRange(bus::get<double>(n, w, "tolerance_hz", m.tolerance_hz), 0.01,
                                   1e3, "dither.tolerance_hz");
  m.window_samples = bus::get<int>(n, w, "window_samples", m.window_samples);
  m.hop_samples = bus::get<int>(n, w, "hop_samples", m.hop_samples);
  m.windows_to_fail = bus::get<int>(n, w, "windows_to_fail", m.windows_to_fail);
  m.windows_to_clear = bus::get<int>(n, w, "windows_to_clear", m.windows_to_clear);
  const YAML::Node a = n ? n["accelerometer"] : YAML::Node();
  checkKeys(a, "dither.accelerometer", {"band_hz", "min_amplitude_mg"});
  band(a, "dither.accelerometer", m.accel_band_low_hz, m.accel_band_high_hz);
  m.accel_min_amplitude_mps2 = bus::get<double>(a, "dither.accelerometer", "min_amplitude_mg",
                                                m.accel_min_amplitude_mps2 / kMilliG) *
                               kMilliG;
  const YAML::Node g = n ? n["gyro"] : YAML::Node();
  checkKeys(g, "dither.gyro", {"check", "band_hz", "min_amplitude_dps"});
  m.check_gyros = bus::get<bool>(g, "dither.gyro", "check", m.check_gyros);
  band(g, "dither.gyro", m.gyro_band_low_hz, m.gyro_band_high_hz);
  m.gyro_min_amplitude_radps =
      bus::get<double>(g, "dither.gyro", "min_amplitude_dps", m.gyro_min_amplitude_radps / kDeg) *
      kDeg;
  const YAML::Node s = n ? n["stillness"] : YAML::Node();
  checkKeys(s, "dither.stillness", {"band_hz", "max_rms_mg"});
  band(s, "dither.stillness", m.motion_band_low_hz, m.motion_band_high_hz);
  m.still_max_rms_mps2 =
      bus::get<double>(s, "dither.stillness", "max_rms_mg", m.still_max_rms_mps2 / kMilliG) *
      kMilliG;
  const YAML::Node act = n ? n["actions"] : YAML::Node();
  checkKeys(act, "dither.actions", {"axis"});
  const auto axis = bus::get<std::string>(act, "dither.actions", "axis", "fail");
  if (axis != "fail" && axis != "none")
    throw bus::ConfigError("configuration dither.actions.axis: '" + axis +
                           "' is not one of fail, none");
  d.fail_axes = axis == "fail";
  try {
    core::DitherMonitor check(m);  // the monitor's own consistency rules, naming the field
  } catch (const std::invalid_argument& e) {
    throw bus::ConfigError(std::string("configuration ") + e.what());
  }
}

/// [deg/sqrt(h)] -> [rad/sqrt(s)]
constexpr double kDegPerSqrtHour = kDeg / 60.0;

void parseParityUnits(const YAML::Node& list, ParityDetectorConfig& d) {
  if (!list || !list.IsSequence())
    throw bus::ConfigError("configuration parity.units must be a list of the IMUs");
  const double dt = 1.0 / d.imu_rate_hz;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string w = "parity.units[" + std::to_string(i) + "]";
    checkKeys(n, w,
              {"sensor_id", "mounting_rpy_deg", "lever_arm_b_m", "gyro_arw_deg_per_sqrth",
               "accel_noise_ug_per_sqrthz"});
    if (!n["sensor_id"]) throw bus::ConfigError("configuration " + w + ".sensor_id is missing");
    const auto id = bus::get<std::uint32_t>(n, w, "sensor_id", 0);
    for (std::uint32_t known : d.sensor_ids)
      if (known == id)
        throw bus::ConfigError("configuration " + w + ".sensor_id " + std::to_string(id) +
                               " is given twice");
    core::ImuArrayUnit u;
    // The unit's axes: rotated from the body by roll, pitch, yaw (body -> unit is the transpose
    // of the unit -> body rotation those angles make), as the simulator's imu_units.
    u.c_u_b = core::dcmFromEuler(bus::getVector3(n, w, "mounting_rpy_deg", kDeg)).transpose();
    u.lever_arm_b_m = bus::getVector3(n, w, "lever_arm_b_m", 1.0);
    const double arw = bus::checkRange(bus::get<double>(n, w, "gyro_arw_deg_per_sqrth", 0.0), 1e-9,
                                       1e3, w + ".gyro_arw_deg_per_sqrth");
    const double vrw = bus::checkRange(bus::get<double>(n, w, "accel_noise_ug_per_sqrthz", 0.0),
                                       1e-6, 1e7, w + ".accel_noise_ug_per_sqrthz");
    u.gyro_sigma_rad = arw * kDegPerSqrtHour * std::sqrt(dt);
    u.accel_sigma_mps = vrw * kMicroG * std::sqrt(dt);
    d.sensor_ids.push_back(id);
    d.units.push_back(u);
  }
}

/// The keys of a parity GLR (parity_glr.hpp) present in block `w`; their ranges are the
/// GLR's own (ParityGlr::make names the key).
void parseParityGlr(const YAML::Node& n, const std::string& w, core::ParityGlrConfig& g) {
  g.onsets = bus::get<int>(n, w, "onsets", g.onsets);
  g.onset_spacing = bus::get<int>(n, w, "onset_spacing", g.onset_spacing);
  g.false_alarm_probability =
      bus::get<double>(n, w, "false_alarm_probability", g.false_alarm_probability);
  g.detection_probability =
      bus::get<double>(n, w, "detection_probability", g.detection_probability);
  g.ambiguity_margin = bus::get<double>(n, w, "ambiguity_margin", g.ambiguity_margin);
  g.ambiguity_correlation =
      bus::get<double>(n, w, "ambiguity_correlation", g.ambiguity_correlation);
}

void parseParity(const YAML::Node& n, ParityDetectorConfig& d) {
  if (!n) return;
  const std::string w = "parity";
  checkKeys(
      n, w,
      {"enabled", "imu_rate_hz", "units", "onsets", "onset_spacing", "false_alarm_probability",
       "detection_probability", "ambiguity_margin", "ambiguity_correlation", "reference_s",
       "reference_time_constant_s", "actions", "alignment_depth"});
  d.enabled = bus::get<bool>(n, w, "enabled", d.enabled);
  d.imu_rate_hz = bus::checkRange(bus::get<double>(n, w, "imu_rate_hz", d.imu_rate_hz), 1.0, 1e5,
                                  "parity.imu_rate_hz");
  core::ImuArrayParityConfig& a = d.array;
  parseParityGlr(n, w, a.glr);
  const double reference_s = bus::checkRange(bus::get<double>(n, w, "reference_s", 60.0), 0.01,
                                             86400.0, "parity.reference_s");
  const double tau_s = bus::checkRange(bus::get<double>(n, w, "reference_time_constant_s", 1800.0),
                                       0.0, 1e7, "parity.reference_time_constant_s");
  a.reference_samples = static_cast<int>(std::lround(reference_s * d.imu_rate_hz));
  a.reference_time_constant_samples = tau_s * d.imu_rate_hz;
  d.alignment_depth =
      static_cast<int>(bus::checkRange(bus::get<double>(n, w, "alignment_depth", d.alignment_depth),
                                       1.0, 1e7, "parity.alignment_depth"));
  const YAML::Node act = n["actions"];
  checkKeys(act, "parity.actions", {"axis"});
  const auto axis = bus::get<std::string>(act, "parity.actions", "axis", "fail");
  if (axis != "fail" && axis != "none")
    throw bus::ConfigError("configuration parity.actions.axis: '" + axis +
                           "' is not one of fail, none");
  d.fail_axes = axis == "fail";
  if (!d.enabled) return;
  parseParityUnits(n["units"], d);
  std::string error;  // the array's own rules (geometry, noise, GLR keys), naming the field
  if (!core::ImuArrayParity::make(d.units, 1.0 / d.imu_rate_hz, a, error))
    throw bus::ConfigError("configuration parity: " + error);
}

void parseReceiverUnits(const YAML::Node& list, ReceiverDetectorConfig& d) {
  if (!list || !list.IsSequence() || list.size() < 2)
    throw bus::ConfigError(
        "configuration receivers.units must be a list of at least two receivers (the first is "
        "the reference)");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node n = list[i];
    const std::string w = "receivers.units[" + std::to_string(i) + "]";
    checkKeys(n, w, {"receiver_id", "antenna_b_m"});
    const auto id = bus::require<std::uint32_t>(n, w, "receiver_id");
    if (std::find(d.receiver_ids.begin(), d.receiver_ids.end(), id) != d.receiver_ids.end())
      throw bus::ConfigError("configuration " + w + ".receiver_id " + std::to_string(id) +
                             " is given twice");
    d.receiver_ids.push_back(id);
    d.antennas_b_m.push_back(bus::getVector3(n, w, "antenna_b_m", 1.0));
  }
}

void parseReceivers(const YAML::Node& n, ReceiverDetectorConfig& d) {
  if (!n) return;
  const std::string w = "receivers";
  checkKeys(n, w,
            {"enabled", "units", "onsets", "onset_spacing", "false_alarm_probability",
             "detection_probability", "ambiguity_margin", "ambiguity_correlation",
             "clock_false_alarm_probability", "clock_bias_noise_m_per_sqrts",
             "clock_drift_noise_mps_per_sqrts", "alignment_depth"});
  d.enabled = bus::get<bool>(n, w, "enabled", d.enabled);
  core::ParityGlrConfig& g = d.glr;
  parseParityGlr(n, w, g);
  core::ReceiverClockConfig& c = d.clock;
  c.false_alarm_probability = bus::checkRange(
      bus::get<double>(n, w, "clock_false_alarm_probability", c.false_alarm_probability), 1e-15,
      0.5, "receivers.clock_false_alarm_probability");
  c.bias_noise_m_per_sqrts = bus::checkRange(
      bus::get<double>(n, w, "clock_bias_noise_m_per_sqrts", c.bias_noise_m_per_sqrts), 0.0, 1e6,
      "receivers.clock_bias_noise_m_per_sqrts");
  c.drift_noise_mps_per_sqrts = bus::checkRange(
      bus::get<double>(n, w, "clock_drift_noise_mps_per_sqrts", c.drift_noise_mps_per_sqrts), 0.0,
      1e6, "receivers.clock_drift_noise_mps_per_sqrts");
  d.alignment_depth =
      static_cast<int>(bus::checkRange(bus::get<double>(n, w, "alignment_depth", d.alignment_depth),
                                       1.0, 1e5, "receivers.alignment_depth"));
  if (!d.enabled) return;
  parseReceiverUnits(n["units"], d);
  // The GLR's own rules (onsets, probabilities), naming the key, on a space of two satellites.
  std::string error;
  const std::optional<core::ParitySpace> space =
      core::ParitySpace::makeCommonMode(core::parity::Measurements::Ones(2), error);
  if (!space || !core::ParityGlr::make(*space, g, error))
    throw bus::ConfigError("configuration receivers: " + error);
}

}  // namespace

FaultManagerConfig parseFaultManagerConfig(const YAML::Node& root) {
  FaultManagerConfig c;
  checkKeys(root, "", {"vehicle_id", "glr", "dither", "parity", "receivers"},
            bus::kParticipantKeys);
  c.vehicle_id = bus::get<std::uint32_t>(root, "", "vehicle_id", c.vehicle_id);
  const YAML::Node g = root["glr"];
  checkKeys(g, "glr",
            {"enabled", "window_epochs", "threshold", "ambiguity_margin", "ambiguity_correlation",
             "rank_tolerance", "hypotheses", "actions", "readmission", "repeats"});
  GlrDetectorConfig& d = c.glr;
  core::GlrConfig& m = d.glr;
  d.enabled = bus::get<bool>(g, "glr", "enabled", d.enabled);
  bus::parseGlrStatistics(g, "glr", m);
  const YAML::Node a = g ? g["actions"] : YAML::Node();
  checkKeys(a, "glr.actions", {"satellite", "imu", "imu_relative_sigma"});
  d.compensation_relative_sigma =
      bus::checkRange(bus::get<double>(a, "glr.actions", "imu_relative_sigma", 0.05), 1e-4, 1.0,
                      "glr.actions.imu_relative_sigma");
  const auto sat = bus::get<std::string>(a, "glr.actions", "satellite", "exclude");
  if (sat != "exclude" && sat != "none")
    throw bus::ConfigError("configuration glr.actions.satellite: '" + sat +
                           "' is not one of exclude, none");
  d.exclude_satellites = sat == "exclude";
  const auto imu = bus::get<std::string>(a, "glr.actions", "imu", "compensate");
  if (imu != "compensate" && imu != "none")
    throw bus::ConfigError("configuration glr.actions.imu: '" + imu +
                           "' is not one of compensate, none");
  d.compensate_imu = imu == "compensate";
  const YAML::Node r = g ? g["readmission"] : YAML::Node();
  checkKeys(r, "glr.readmission", {"pass_sigma", "pass_time_s"});
  d.readmit_sigma = bus::checkRange(bus::get<double>(r, "glr.readmission", "pass_sigma", 3.0), 0.1,
                                    100.0, "glr.readmission.pass_sigma");
  d.readmit_after_s = bus::checkRange(bus::get<double>(r, "glr.readmission", "pass_time_s", 30.0),
                                      0.0, 86400.0, "glr.readmission.pass_time_s");
  const YAML::Node rep = g ? g["repeats"] : YAML::Node();
  checkKeys(rep, "glr.repeats", {"window_s", "escalate_after"});
  d.repeats.window_s =
      bus::checkRange(bus::get<double>(rep, "glr.repeats", "window_s", d.repeats.window_s), 1.0,
                      86400.0, "glr.repeats.window_s");
  d.repeats.escalate_after = static_cast<int>(bus::checkRange(
      bus::get<double>(rep, "glr.repeats", "escalate_after", d.repeats.escalate_after), 1.0, 100.0,
      "glr.repeats.escalate_after"));
  parseDither(root["dither"], c.dither);
  parseParity(root["parity"], c.parity);
  parseReceivers(root["receivers"], c.receivers);
  return c;
}

}  // namespace navbus::fault_manager
