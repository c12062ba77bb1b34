#include "fault_config.hpp"

#include <set>
#include <string>

#include "navbus/bus/config.hpp"

namespace navbus::fault_manager {

namespace {

void checkKeys(const YAML::Node& node, const std::string& where,
               const std::set<std::string>& allowed) {
  if (!node || node.IsNull()) return;  // absent or empty: every default
  if (!node.IsMap()) throw bus::ConfigError("configuration " + where + " must be a map");
  for (const auto& kv : node) {
    const auto key = kv.first.as<std::string>();
    if (allowed.count(key) == 0)
      throw bus::ConfigError("configuration " + where + "." + key + ": unknown key");
  }
}

}  // namespace

FaultManagerConfig parseFaultManagerConfig(const YAML::Node& root) {
  FaultManagerConfig c;
  c.vehicle_id = bus::get<std::uint32_t>(root, "", "vehicle_id", c.vehicle_id);
  const YAML::Node g = root["glr"];
  checkKeys(g, "glr",
            {"enabled", "window_epochs", "threshold", "ambiguity_margin", "ambiguity_correlation",
             "rank_tolerance", "hypotheses", "actions", "readmission"});
  GlrDetectorConfig& d = c.glr;
  core::GlrConfig& m = d.glr;
  d.enabled = bus::get<bool>(g, "glr", "enabled", d.enabled);
  m.window = static_cast<int>(bus::checkRange(bus::get<double>(g, "glr", "window_epochs", m.window),
                                              1, core::glr::kMaxWindow, "glr.window_epochs"));
  m.threshold = bus::checkRange(bus::get<double>(g, "glr", "threshold", m.threshold), 0.1, 1e6,
                                "glr.threshold");
  m.ambiguity_margin =
      bus::checkRange(bus::get<double>(g, "glr", "ambiguity_margin", m.ambiguity_margin), 0.0, 1e3,
                      "glr.ambiguity_margin");
  m.ambiguity_correlation =
      bus::checkRange(bus::get<double>(g, "glr", "ambiguity_correlation", m.ambiguity_correlation),
                      0.0, 1.0, "glr.ambiguity_correlation");
  m.rank_tolerance = bus::checkRange(bus::get<double>(g, "glr", "rank_tolerance", m.rank_tolerance),
                                     1e-15, 0.5, "glr.rank_tolerance");
  const YAML::Node h = g ? g["hypotheses"] : YAML::Node();
  checkKeys(h, "glr.hypotheses", {"imu_steps", "range_steps", "range_ramps", "rate_steps"});
  m.imu_steps = bus::get<bool>(h, "glr.hypotheses", "imu_steps", m.imu_steps);
  m.range_steps = bus::get<bool>(h, "glr.hypotheses", "range_steps", m.range_steps);
  m.range_ramps = bus::get<bool>(h, "glr.hypotheses", "range_ramps", m.range_ramps);
  m.rate_steps = bus::get<bool>(h, "glr.hypotheses", "rate_steps", m.rate_steps);
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
  return c;
}

}  // namespace navbus::fault_manager
