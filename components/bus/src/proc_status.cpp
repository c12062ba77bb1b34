#include "navbus/bus/proc_status.hpp"

#include <cstdlib>
#include <fstream>

namespace navbus::bus {

long procStatusKilobytes(const std::string& process, const std::string& name) {
  std::ifstream status("/proc/" + process + "/status");
  const std::string key = name + ":";
  for (std::string line; std::getline(status, line);) {
    if (line.rfind(key, 0) == 0) return std::strtol(line.c_str() + key.size(), nullptr, 10);
  }
  return -1;
}

}  // namespace navbus::bus
