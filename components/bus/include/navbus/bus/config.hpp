// YAML configuration helpers: every error names the key and the offending value.
#pragma once

#include <initializer_list>
#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "navbus/core/integrity/glr.hpp"
#include "navbus/core/math/earth.hpp"

namespace navbus::bus {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

YAML::Node loadYamlFile(const std::string& path);

/// A ConfigError whose message already names the configuration file.
class ConfigFileError : public ConfigError {
 public:
  ConfigFileError(const std::string& file, const std::string& what)
      : ConfigError("configuration file '" + file + "'" + what) {}
};

/// A key no parser reads: a typo that would otherwise be silently ignored.
class UnknownKeyError : public ConfigError {
 public:
  explicit UnknownKeyError(const std::string& key_path)
      : ConfigError("configuration " + key_path + ": unknown key"), key_path_(key_path) {}
  /// Dotted path of the key, list elements as [i] ("glr.actions.imu", "faults[2].slope").
  const std::string& keyPath() const { return key_path_; }

 private:
  std::string key_path_;
};

/// Throws UnknownKeyError for the first key of the map `node` (at `where`, "" for the top
/// level) that is in neither `allowed` nor `also`; ConfigError if `node` is present but not a
/// map.
void checkKeys(const YAML::Node& node, const std::string& where,
               std::initializer_list<const char*> allowed,
               std::initializer_list<const char*> also = {});

/// The top-level keys every participant's configuration may carry (participantOptions()).
inline constexpr std::initializer_list<const char*> kParticipantKeys = {
    "domain_id",       "qos_file",         "participant_profile", "security_identity",
    "health_period_s", "discovery_server", "ros2_names",          "realtime"};

/// The file of `path`'s extends chain that spells `key_path` (the most derived one; `path`
/// itself when none does).
std::string fileDefiningKey(const std::string& path, const std::string& key_path);

/// A ConfigError from parsing the configuration file `path`, re-thrown with the file named
/// (for an unknown key, the file of the extends chain that holds it).
[[noreturn]] void rethrowNamingFile(const std::string& path, const ConfigError& e);

/// Loads `path` (with extends) and parses it; errors name the file.
template <class Parse>
auto parseFile(const std::string& path, Parse&& parse) -> decltype(parse(YAML::Node())) {
  const YAML::Node node = loadYamlFile(path);
  try {
    return parse(node);
  } catch (const ConfigError& e) {
    rethrowNamingFile(path, e);
  }
}

/// Loads a YAML file; throws ConfigError naming the file on failure. A top-level
/// `extends: other.yaml` (relative path) loads that file first; this file's keys override its
/// keys (maps merge recursively, lists and scalars replace).
YAML::Node loadYamlFile(const std::string& path);

/// Throws ConfigError (naming `where` and the text found) unless `node` is absent, empty or a
/// map: keys cannot be looked up in a scalar or a list.
void requireMapOrAbsent(const YAML::Node& node, const std::string& where);

/// `node`, the value at `path` ("dither.band_hz[0]"), as T; throws ConfigError (naming `path`
/// and the text found) when it is not convertible.
template <class T>
T as(const YAML::Node& node, const std::string& path) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw ConfigError("configuration " + path + ": cannot read value '" + YAML::Dump(node) + "'");
  }
}

/// Reads `key` of `node` as T; returns `fallback` when the key is absent; throws ConfigError
/// (naming `where.key` and the text found) when present but not convertible.
template <class T>
T get(const YAML::Node& node, const std::string& where, const std::string& key, const T& fallback) {
  requireMapOrAbsent(node, where);
  if (!node || !node[key]) {
    return fallback;
  }
  return as<T>(node[key], where + "." + key);
}

/// As get(), but the key must be present.
template <class T>
T require(const YAML::Node& node, const std::string& where, const std::string& key) {
  requireMapOrAbsent(node, where);
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

/// The GLR's statistics keys of `node` (window_epochs, threshold, ambiguity_margin,
/// ambiguity_correlation, rank_tolerance, hypotheses), over the defaults in `m`: the fault
/// manager's detector and the filter's protection levels read the same keys. The caller
/// checks the node's key set.
void parseGlrStatistics(const YAML::Node& node, const std::string& where, core::GlrConfig& m);

}  // namespace navbus::bus
