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

}  // namespace navbus::bus
