// Writes the seed corpora of the fuzz targets: one valid serialized sample of each topic type
// (selector byte first, as fuzz_topics reads it) into <dir>/topics, and each configuration
// file given on the command line (selector byte chosen by its kind) into <dir>/config.
// Usage: navbus_fuzz_seeds <dir> [participant|sim|filter|fault:<file.yaml> ...]
#include <cstdint>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/HealthPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "navbus/bus/conversions.hpp"

namespace {

using eprosima::fastrtps::rtps::SerializedPayload_t;

bool writeFile(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) std::cerr << "navbus_fuzz_seeds: cannot write " << path << "\n";
  return static_cast<bool>(out);
}

template <class PubSubType>
bool writeSample(const std::string& dir, std::uint8_t selector, typename PubSubType::type s) {
  PubSubType type;
  SerializedPayload_t payload(type.getSerializedSizeProvider(&s)());
  if (!type.serialize(&s, &payload)) return false;
  std::vector<char> bytes{static_cast<char>(selector)};
  bytes.insert(bytes.end(), payload.data, payload.data + payload.length);
  return writeFile(dir + "/topics/" + type.getName(), bytes);
}

navbus::GnssObservationEpoch epoch() {
  navbus::GnssObservationEpoch e;
  e.receiver_id(1);
  e.seq(7);
  e.time_gps_ns(1'400'000'000'000'000'000ULL);
  for (std::uint16_t sv = 1; sv <= 8; ++sv) {
    navbus::GnssSatelliteMeasurement m;
    m.sv_id(sv);
    m.pseudorange_m(2.2e7 + 1.0e5 * sv);
    m.pseudorange_rate_mps(-300.0 + 50.0 * sv);
    m.sat_pos_ecef_m({2.0e7, 1.0e7 + 1.0e6 * sv, 1.2e7});
    m.sat_vel_ecef_mps({-1000.0, 2500.0, 800.0});
    m.cn0_dbhz(45.0);
    m.pseudorange_sigma_m(3.0);
    m.pseudorange_rate_sigma_mps(0.1);
    m.valid(true);
    e.satellites().push_back(m);
  }
  return e;
}

navbus::FilterDiagnostics diagnostics() {
  navbus::FilterDiagnostics d;
  d.vehicle_id(1);
  d.seq(3);
  d.time_gps_ns(1'400'000'001'000'000'000ULL);
  navbus::bus::fillStateLayout(d);
  const std::size_t n = d.n(), m = 4;
  d.m(static_cast<std::uint16_t>(m));
  for (std::size_t r = 0; r < m; ++r) {
    navbus::MeasurementRow row;
    row.kind(navbus::MEAS_PSEUDORANGE);
    row.sv_id(static_cast<std::uint16_t>(r + 1));
    row.used(true);
    d.rows().push_back(row);
    d.innovation().push_back(0.5);
    d.test_ratio().push_back(0.1);
  }
  for (std::size_t i = 0; i < m * m; ++i)
    d.innovation_cov().push_back(i % (m + 1) == 0 ? 9.0 : 0.0);
  d.h().assign(m * n, 0.1);
  d.k().assign(n * m, 0.01);
  for (std::size_t i = 0; i < n * n; ++i) d.phi().push_back(i % (n + 1) == 0 ? 1.0 : 0.0);
  return d;
}

bool writeTopicSeeds(const std::string& dir) {
  navbus::ImuIncrement inc;
  inc.sensor_id(1);
  inc.seq(1);
  inc.time_gps_ns(1'400'000'000'005'000'000ULL);
  inc.interval_ns(5'000'000);
  inc.delta_vel_b_mps({0.0, 0.0, -0.049});
  inc.delta_angle_b_rad({1e-7, -2e-7, 3e-7});
  navbus::ImuRawBlock raw;
  raw.sensor_id(1);
  raw.seq(1);
  raw.first_sample_time_gps_ns(inc.time_gps_ns());
  raw.sample_period_ns(416'667);
  raw.samples().resize(12);
  navbus::GnssFix fix;
  fix.receiver_id(1);
  fix.seq(1);
  fix.time_gps_ns(inc.time_gps_ns());
  fix.latitude_rad(0.5);
  fix.pos_ecef_m({4.0e6, 1.0e6, 4.8e6});
  fix.pos_sigma_ned_m({3.0, 3.0, 5.0});
  fix.vel_sigma_ned_mps({0.1, 0.1, 0.2});
  fix.num_satellites_used(8);
  fix.valid(true);
  navbus::StarTrackerAttitude star;
  star.tracker_id(1);
  star.seq(1);
  star.time_gps_ns(inc.time_gps_ns());
  star.q_b_to_i({1.0, 0.0, 0.0, 0.0});
  star.sigma_b_rad({2.4e-5, 2.4e-5, 1.2e-4});
  star.valid(true);
  navbus::NavigationSolution sol;
  sol.vehicle_id(1);
  navbus::FaultDecision dec;
  dec.decision_id(1);
  dec.event(navbus::EVENT_FAULT_DETECTED);
  dec.source(navbus::SOURCE_SATELLITE);
  dec.sv_id(13);
  dec.candidates().resize(2);
  dec.detector("glr");
  navbus::FilterCommand cmd;
  cmd.command_id(1);
  cmd.kind(navbus::CMD_EXCLUDE_SATELLITE);
  cmd.sv_id(13);
  cmd.issuer("fault-manager");
  navbus::Health health;
  health.participant("navbus-filter");
  health.inputs().resize(1);
  health.inputs()[0].topic("navbus/imu/increment");
  health.inputs()[0].rejected().resize(1);
  navbus::ImuIncrementBlock block;
  block.sensor_id(inc.sensor_id());
  block.seq(1);
  block.increments().assign(3, inc);
  // Selectors in the order of fuzz_topics.cpp's kTypes.
  return writeSample<navbus::ImuIncrementPubSubType>(dir, 0, inc) &&
         writeSample<navbus::ImuRawBlockPubSubType>(dir, 1, raw) &&
         writeSample<navbus::GnssObservationEpochPubSubType>(dir, 2, epoch()) &&
         writeSample<navbus::GnssFixPubSubType>(dir, 3, fix) &&
         writeSample<navbus::StarTrackerAttitudePubSubType>(dir, 4, star) &&
         writeSample<navbus::NavigationSolutionPubSubType>(dir, 5, sol) &&
         writeSample<navbus::FilterDiagnosticsPubSubType>(dir, 6, diagnostics()) &&
         writeSample<navbus::FaultDecisionPubSubType>(dir, 7, dec) &&
         writeSample<navbus::FilterCommandPubSubType>(dir, 8, cmd) &&
         writeSample<navbus::HealthPubSubType>(dir, 9, health) &&
         writeSample<navbus::ImuIncrementBlockPubSubType>(dir, 10, block);
}

/// "kind:path": the file's text behind the selector of its parser (fuzz_config.cpp's order).
bool writeConfigSeed(const std::string& dir, const std::string& arg, int index) {
  static const std::map<std::string, char> kSelector = {
      {"participant", 0}, {"sim", 1}, {"filter", 2}, {"fault", 3}};
  const auto colon = arg.find(':');
  const auto kind = kSelector.find(arg.substr(0, colon));
  if (colon == std::string::npos || kind == kSelector.end()) {
    std::cerr << "navbus_fuzz_seeds: argument '" << arg
              << "' is not <participant|sim|filter|fault>:<file>\n";
    return false;
  }
  std::ifstream in(arg.substr(colon + 1), std::ios::binary);
  if (!in) {
    std::cerr << "navbus_fuzz_seeds: cannot read " << arg.substr(colon + 1) << "\n";
    return false;
  }
  std::vector<char> bytes{kind->second};
  bytes.insert(bytes.end(), std::istreambuf_iterator<char>(in), {});
  return writeFile(dir + "/config/seed" + std::to_string(index), bytes);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: navbus_fuzz_seeds <dir> [participant|sim|filter|fault:<file> ...]\n";
    return 2;
  }
  const std::string dir = argv[1];
  bool ok = writeTopicSeeds(dir);
  for (int i = 2; i < argc; ++i) ok = writeConfigSeed(dir, argv[i], i) && ok;
  return ok ? 0 : 1;
}
