#include "filter_config.hpp"

#include <cmath>

#include "navbus/bus/config.hpp"
#include "navbus/core/rotation.hpp"

namespace navbus::nav_filter {

namespace {
constexpr double kDeg = M_PI / 180.0;

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
  s.position.latitude_rad =
      bus::checkRange(bus::require<double>(init, "initial_state", "latitude_deg"), -90, 90,
                      "initial_state.latitude_deg") *
      kDeg;
  s.position.longitude_rad =
      bus::checkRange(bus::require<double>(init, "initial_state", "longitude_deg"), -180, 180,
                      "initial_state.longitude_deg") *
      kDeg;
  s.position.height_m = bus::checkRange(bus::require<double>(init, "initial_state", "height_m"),
                                        -500, 5e6, "initial_state.height_m");
  const auto vel =
      bus::get<std::vector<double>>(init, "initial_state", "vel_ned_mps", {0.0, 0.0, 0.0});
  if (vel.size() != 3)
    throw bus::ConfigError("configuration initial_state.vel_ned_mps must have 3 elements");
  s.vel_ned_mps = Eigen::Vector3d(vel[0], vel[1], vel[2]);
  const Eigen::Vector3d rpy(
      bus::checkRange(bus::get<double>(init, "initial_state", "roll_deg", 0.0), -180, 180,
                      "initial_state.roll_deg") *
          kDeg,
      bus::checkRange(bus::get<double>(init, "initial_state", "pitch_deg", 0.0), -90, 90,
                      "initial_state.pitch_deg") *
          kDeg,
      bus::checkRange(bus::get<double>(init, "initial_state", "yaw_deg", 0.0), -180, 360,
                      "initial_state.yaw_deg") *
          kDeg);
  s.q_b_to_n = Eigen::Quaterniond(core::dcmFromEuler(rpy));

  const YAML::Node inputs = root["inputs"];
  if (!inputs) throw bus::ConfigError("configuration inputs is missing");
  c.imu = *input(inputs, "imu", true);
  c.gnss_observations = input(inputs, "gnss_observations", false);
  c.gnss_fix = input(inputs, "gnss_fix", false);
  c.star_tracker = input(inputs, "star_tracker", false);
  return c;
}

}  // namespace navbus::nav_filter
