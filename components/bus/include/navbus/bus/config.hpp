// YAML configuration helpers: every error names the key and the offending value.
#pragma once

#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "navbus/core/earth.hpp"

namespace navbus::bus {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Loads a YAML file; throws ConfigError naming the file on failure. A top-level
/// `extends: other.yaml` (relative path) loads that file first; this file's keys override its
/// keys (maps merge recursively, lists and scalars replace).
YAML::Node loadYamlFile(const std::string& path);

/// Reads `key` of `node` as T; returns `fallback` when the key is absent; throws ConfigError
/// (naming `where.key` and the text found) when present but not convertible.
template <class T>
T get(const YAML::Node& node, const std::string& where, const std::string& key, const T& fallback) {
  if (!node || !node[key]) {
    return fallback;
  }
  try {
    return node[key].as<T>();
  } catch (const YAML::Exception&) {
    throw ConfigError("configuration " + where + "." + key + ": cannot read value '" +
                      YAML::Dump(node[key]) + "'");
  }
}

/// As get(), but the key must be present.
template <class T>
T require(const YAML::Node& node, const std::string& where, const std::string& key) {
  if (!node || !node[key]) {
    throw ConfigError("configuration " + where + "." + key + " is missing");
  }
  return get<T>(node, where, key, T{});
}

/// Throws ConfigError unless lo <= value <= hi.
double checkRange(double value, double lo, double hi, const std::string& name);

/// `where.key` as a 3-element list times `scale` (unit conversion); `fallback` when absent.
Eigen::Vector3d getVector3(const YAML::Node& node, const std::string& where, const std::string& key,
                           double scale, const Eigen::Vector3d& fallback = Eigen::Vector3d::Zero());

/// latitude_deg, longitude_deg and height_m of `node`, converted to radians; `fallback` for
/// absent keys, or all required when `fallback` is null.
core::earth::Geodetic getGeodeticDeg(const YAML::Node& node, const std::string& where,
                                     const core::earth::Geodetic* fallback);

/// roll_deg, pitch_deg and yaw_deg of `node` (0 when absent), converted to radians.
Eigen::Vector3d getRollPitchYawDeg(const YAML::Node& node, const std::string& where);

}  // namespace navbus::bus
