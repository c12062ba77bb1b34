#include "navbus/bus/config.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

namespace navbus::bus {

YAML::Node loadYamlFile(const std::string& path) {
  if (!std::ifstream(path).good()) {
    throw ConfigError("configuration file '" + path + "' cannot be read");
  }
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw ConfigError("configuration file '" + path + "': " + e.what());
  }
}

double checkRange(double value, double lo, double hi, const std::string& name) {
  if (!std::isfinite(value) || value < lo || value > hi) {
    std::ostringstream out;
    out << "configuration " << name << " = " << value << " is outside [" << lo << ", " << hi << "]";
    throw ConfigError(out.str());
  }
  return value;
}

Eigen::Vector3d getVector3(const YAML::Node& node, const std::string& where, const std::string& key,
                           double scale, const Eigen::Vector3d& fallback) {
  if (!node || !node[key]) return fallback;
  const auto v = get<std::vector<double>>(node, where, key, {});
  if (v.size() != 3) {
    throw ConfigError("configuration " + where + "." + key + " must have 3 elements, has " +
                      std::to_string(v.size()));
  }
  return Eigen::Vector3d(v[0], v[1], v[2]) * scale;
}

core::earth::Geodetic getGeodeticDeg(const YAML::Node& node, const std::string& where,
                                     const core::earth::Geodetic* fallback) {
  constexpr double kDeg = M_PI / 180.0;
  auto value = [&](const char* key, double fallback_value) {
    return fallback ? get<double>(node, where, key, fallback_value)
                    : require<double>(node, where, key);
  };
  core::earth::Geodetic g;
  g.latitude_rad = checkRange(value("latitude_deg", fallback ? fallback->latitude_rad / kDeg : 0.0),
                              -90, 90, where + ".latitude_deg") *
                   kDeg;
  g.longitude_rad =
      checkRange(value("longitude_deg", fallback ? fallback->longitude_rad / kDeg : 0.0), -180, 180,
                 where + ".longitude_deg") *
      kDeg;
  g.height_m = checkRange(value("height_m", fallback ? fallback->height_m : 0.0), -500, 5e6,
                          where + ".height_m");
  return g;
}

Eigen::Vector3d getRollPitchYawDeg(const YAML::Node& node, const std::string& where) {
  constexpr double kDeg = M_PI / 180.0;
  return Eigen::Vector3d(
      checkRange(get<double>(node, where, "roll_deg", 0.0), -180, 180, where + ".roll_deg") * kDeg,
      checkRange(get<double>(node, where, "pitch_deg", 0.0), -89.9, 89.9, where + ".pitch_deg") *
          kDeg,
      checkRange(get<double>(node, where, "yaw_deg", 0.0), -180, 360, where + ".yaw_deg") * kDeg);
}

}  // namespace navbus::bus
