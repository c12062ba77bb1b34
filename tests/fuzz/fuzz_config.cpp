// libFuzzer target: the configuration parsers (participant options, simulator scenario,
// filter, fault manager) on arbitrary YAML text.
//
// Input: one selector byte (which parser, modulo the number of parsers), then the text.
// Property beyond "no crash, no leak, no undefined behaviour": bad input ends in a
// navbus::bus::ConfigError (whose message names the key and the value) or, for text that is
// not YAML, yaml-cpp's ParserException; any other exception escaping a parser is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <typeinfo>

#include <yaml-cpp/yaml.h>

#include "navbus/bus/app.hpp"
#include "navbus/bus/config.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"

namespace {

void parseParticipant(const YAML::Node& root) {
  (void)navbus::bus::participantOptions(navbus::bus::CommonOptions{}, root, "fuzz");
}
void parseSim(const YAML::Node& root) {
  (void)navbus::sensor_sim::parseSimConfig(root);
}
void parseFilter(const YAML::Node& root) {
  (void)navbus::nav_filter::parseFilterConfig(root);
}
void parseFaultManager(const YAML::Node& root) {
  (void)navbus::fault_manager::parseFaultManagerConfig(root);
}

using Parse = void (*)(const YAML::Node&);
constexpr Parse kParsers[] = {parseParticipant, parseSim, parseFilter, parseFaultManager};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  constexpr std::size_t kCount = sizeof(kParsers) / sizeof(kParsers[0]);
  const Parse parse = kParsers[data[0] % kCount];
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException&) {
    return 0;  // not YAML: loadYamlFile reports it naming the file
  }
  try {
    parse(root);
  } catch (const navbus::bus::ConfigError&) {
    // the documented outcome of bad input
  } catch (const std::exception& e) {
    // An error that does not name the key: a finding.
    std::fprintf(stderr, "fuzz_config: %s escaped the parser: %s\n", typeid(e).name(), e.what());
    std::abort();
  }
  return 0;
}
