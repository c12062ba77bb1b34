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
  c.gnss_fix = input(inputs, "gnss_fix", false);
  c.star_tracker = input(inputs, "star_tracker", false);
  return c;
}

}  // namespace navbus::nav_filter
