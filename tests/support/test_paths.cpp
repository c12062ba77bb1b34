#include "test_paths.hpp"

namespace navbus::test_paths {

const char* sourceDir() {
  return NAVBUS_SOURCE_DIR;
}
const char* scenarioDir() {
  return NAVBUS_SOURCE_DIR "/sim/scenarios";
}
const char* configDir() {
  return NAVBUS_SOURCE_DIR "/config";
}
const char* credentialsDir() {
  return NAVBUS_CREDENTIALS_DIR;
}
const char* rinexDir() {
  return NAVBUS_SOURCE_DIR "/tests/data/rinex";
}
const char* realDir() {
  return NAVBUS_SOURCE_DIR "/tests/data/real";
}
const char* workDir() {
  return NAVBUS_WORK_DIR;
}
const char* rnx2rtkp() {
  return NAVBUS_RNX2RTKP;
}
const char* convbin() {
  return NAVBUS_CONVBIN;
}
const char* sensorSimExe() {
  return NAVBUS_SENSOR_SIM_EXE;
}
const char* filterExe() {
  return NAVBUS_FILTER_EXE;
}
const char* faultManagerExe() {
  return NAVBUS_FAULT_MANAGER_EXE;
}
const char* toolExe() {
  return NAVBUS_TOOL_EXE;
}

}  // namespace navbus::test_paths
