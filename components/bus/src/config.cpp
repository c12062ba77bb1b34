#include "navbus/bus/config.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace navbus::bus {

namespace {
/// Copies `over` onto `base`: maps merge key by key, anything else replaces.
YAML::Node merge(YAML::Node base, const YAML::Node& over) {
  if (!base.IsMap() || !over.IsMap()) return YAML::Clone(over);
  for (const auto& kv : over) {
    const std::string key = as<std::string>(kv.first, "<key>");
    base[key] = base[key] ? merge(YAML::Clone(base[key]), kv.second) : YAML::Clone(kv.second);
  }
  return base;
}

YAML::Node loadWithExtends(const std::filesystem::path& path, int depth) {
  if (depth > 8) throw ConfigFileError(path.string(), ": 'extends' nested too deeply");
  if (!std::ifstream(path).good()) {
    throw ConfigFileError(path.string(), " cannot be read");
  }
  YAML::Node node;
  try {
    node = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw ConfigFileError(path.string(), std::string(": ") + e.what());
  }
  if (!node.IsMap() || !node["extends"]) return node;
  // `extends: base.yaml` (relative to this file): this file's keys override the base's.
  const std::filesystem::path base_path =
      path.parent_path() / as<std::string>(node["extends"], "extends");
  YAML::Node base = loadWithExtends(base_path, depth + 1);
  node.remove("extends");
  return merge(base, node);
}
}  // namespace

YAML::Node loadYamlFile(const std::string& path) {
  return loadWithExtends(path, 0);
}

void requireMapOrAbsent(const YAML::Node& node, const std::string& where) {
  if (!node || node.IsNull() || node.IsMap()) return;
  throw ConfigError("configuration " + (where.empty() ? std::string("file") : where) +
                    " must be a map of keys, found '" + YAML::Dump(node) + "'");
}

void checkKeys(const YAML::Node& node, const std::string& where,
               std::initializer_list<const char*> allowed,
               std::initializer_list<const char*> also) {
  requireMapOrAbsent(node, where);
  if (!node || node.IsNull()) return;  // absent or empty: every default
  for (const auto& kv : node) {
    const auto key = as<std::string>(kv.first, (where.empty() ? "" : where + ".") + "<key>");
    auto is_key = [&key](const char* k) { return key == k; };
    const bool known = std::any_of(allowed.begin(), allowed.end(), is_key) ||
                       std::any_of(also.begin(), also.end(), is_key);
    if (!known) throw UnknownKeyError(where.empty() ? key : where + "." + key);
  }
}

namespace {
/// The node at a dotted key path with [i] list indices; an undefined node when absent.
YAML::Node nodeAt(YAML::Node node, const std::string& key_path) {
  std::stringstream parts(key_path);
  std::string part;
  while (std::getline(parts, part, '.')) {
    const std::size_t bracket = part.find('[');
    const std::string key = part.substr(0, bracket);
    if (!node.IsMap() || !node[key]) return YAML::Node(YAML::NodeType::Undefined);
    node = node[key];
    if (bracket != std::string::npos) {
      const std::size_t i = std::stoul(part.substr(bracket + 1));
      if (!node.IsSequence() || i >= node.size()) return YAML::Node(YAML::NodeType::Undefined);
      node = node[i];
    }
  }
  return node;
}
}  // namespace

std::string fileDefiningKey(const std::string& path, const std::string& key_path) {
  std::filesystem::path file = path;
  for (int depth = 0; depth <= 8; ++depth) {
    YAML::Node own;
    try {
      own = YAML::LoadFile(file.string());
    } catch (const YAML::Exception&) {
      break;
    }
    if (nodeAt(own, key_path).IsDefined()) return file.string();
    if (!own.IsMap() || !own["extends"]) break;
    file = file.parent_path() / as<std::string>(own["extends"], "extends");
  }
  return path;
}

void rethrowNamingFile(const std::string& path, const ConfigError& e) {
  if (const auto* named = dynamic_cast<const ConfigFileError*>(&e)) throw *named;
  const auto* unknown = dynamic_cast<const UnknownKeyError*>(&e);
  const std::string file = unknown ? fileDefiningKey(path, unknown->keyPath()) : path;
  throw ConfigFileError(file, std::string(": ") + e.what());
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

void parseGlrStatistics(const YAML::Node& g, const std::string& w, core::GlrConfig& m) {
  m.window = static_cast<int>(checkRange(get<double>(g, w, "window_epochs", m.window), 1,
                                         core::glr::kMaxWindow, w + ".window_epochs"));
  m.threshold = checkRange(get<double>(g, w, "threshold", m.threshold), 0.1, 1e6, w + ".threshold");
  m.ambiguity_margin = checkRange(get<double>(g, w, "ambiguity_margin", m.ambiguity_margin), 0.0,
                                  1e3, w + ".ambiguity_margin");
  m.ambiguity_correlation =
      checkRange(get<double>(g, w, "ambiguity_correlation", m.ambiguity_correlation), 0.0, 1.0,
                 w + ".ambiguity_correlation");
  m.rank_tolerance = checkRange(get<double>(g, w, "rank_tolerance", m.rank_tolerance), 1e-15, 0.5,
                                w + ".rank_tolerance");
  const YAML::Node h = g ? g["hypotheses"] : YAML::Node();
  const std::string wh = w + ".hypotheses";
  checkKeys(h, wh,
            {"imu_steps", "range_steps", "range_ramps", "rate_steps", "per_receiver_satellites"});
  m.imu_steps = get<bool>(h, wh, "imu_steps", m.imu_steps);
  m.range_steps = get<bool>(h, wh, "range_steps", m.range_steps);
  m.range_ramps = get<bool>(h, wh, "range_ramps", m.range_ramps);
  m.rate_steps = get<bool>(h, wh, "rate_steps", m.rate_steps);
  m.per_receiver_satellites =
      get<bool>(h, wh, "per_receiver_satellites", m.per_receiver_satellites);
}

}  // namespace navbus::bus
