#include "filter_config.hpp"

#include <cmath>

#include "navbus/bus/config.hpp"
#include "navbus/core/rotation.hpp"

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
  InputConfig c;
  c.id = bus::require<std::uint32_t>(n, where, "id");
  c.period_ns = seconds(
      bus::checkRange(bus::require<double>(n, where, "period_s"), 1e-4, 60.0, where + ".period_s"));
  return c;
}
}  // namespace

FilterConfig parseFilterConfig(const YAML::Node& root) {
  FilterConfig c;
  c.vehicle_id = bus::get<std::uint32_t>(root, "", "vehicle_id", 1);
  const double rate = bus::checkRange(bus::get<double>(root, "", "solution_rate_hz", 10.0), 1.0,
                                      1000.0, "solution_rate_hz");
  c.solution_period_ns = seconds(1.0 / rate);
  c.sequencer_max_wait_ns =
      seconds(bus::checkRange(bus::get<double>(root, "", "sequencer_max_wait_s", 0.5), 0.001, 60.0,
                              "sequencer_max_wait_s"));

  const YAML::Node init = root["initial_state"];
  if (!init) throw bus::ConfigError("configuration initial_state is missing");
  auto& s = c.initial_state;
  s.position = bus::getGeodeticDeg(init, "initial_state", nullptr);
  s.vel_ned_mps = bus::getVector3(init, "initial_state", "vel_ned_mps", 1.0);
  const Eigen::Vector3d rpy = bus::getRollPitchYawDeg(init, "initial_state");
  s.q_b_to_n = Eigen::Quaterniond(core::dcmFromEuler(rpy));

  const YAML::Node inputs = root["inputs"];
  if (!inputs) throw bus::ConfigError("configuration inputs is missing");
  c.imu = *input(inputs, "imu", true);
  c.gnss_observations = input(inputs, "gnss_observations", false);

  const std::string mode = bus::get<std::string>(root, "", "mode", "inertial_only");
  if (mode == "inertial_only") {
    c.estimator = Estimator::kInertialOnly;
  } else if (mode == "tightly_coupled") {
    c.estimator = Estimator::kTightlyCoupled;
    if (!c.gnss_observations) {
      throw bus::ConfigError("configuration mode = tightly_coupled needs inputs.gnss_observations");
    }
  } else {
    throw bus::ConfigError("configuration mode = '" + mode +
                           "' is not inertial_only or tightly_coupled");
  }
  // EKF parameters (both modes propagate the covariance), in the units of seed 000s error budget.
  const YAML::Node tc = root["ekf"];
  constexpr double kDeg = M_PI / 180.0;
  constexpr double kMicroG = 9.80665e-6;
  auto& t = c.tightly_coupled;
  const std::string w = "ekf";
  const std::string gravity = bus::get<std::string>(tc, w, "gravity", "wgs84");
  if (gravity != "wgs84" && gravity != "point_mass") {
    throw bus::ConfigError("configuration ekf.gravity = '" + gravity +
                           "' is not wgs84 or point_mass");
  }
  t.gravity = gravity == "wgs84" ? core::earth::GravityModel::kWgs84Normal
                                 : core::earth::GravityModel::kPointMass;
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
  t.gate_sigma =
      bus::checkRange(bus::get<double>(tc, w, "gate_sigma", 5.0), 1.0, 1e3, "ekf.gate_sigma");
  c.initial_clock_bias_m = bus::get<double>(tc, w, "initial_clock_bias_m", 0.0);
  c.initial_clock_drift_mps = bus::get<double>(tc, w, "initial_clock_drift_mps", 0.0);
  c.gnss_fix = input(inputs, "gnss_fix", false);
  c.star_tracker = input(inputs, "star_tracker", false);
  return c;
}

}  // namespace navbus::nav_filter
