// The offline runner (`navbus offline`, no DDS) and the three participants over the bus give
// bit-identical solutions for the same scenario, seed and filter configuration (DESIGN.md,
// Determinism). Two scenarios: the seed-004 land vehicle with the multi-dimensional filter
// (ZUPT, NHC, stage switches, resets) and 40 s of the seed-001 LEO with GNSS fixes and the
// star tracker in the federated structure.
#include <fstream>

#include <gtest/gtest.h>
#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "formatters.hpp"
#include "harness.hpp"

using namespace navbus;
using namespace std::chrono_literals;

namespace {

std::vector<std::string> readCsvRows(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> rows;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) rows.push_back(line);
  return rows;
}

struct Case {
  int domain;
  std::string scenario;  ///< file under sim/scenarios
  std::string filter;    ///< file under config
  std::string filter_extra;
  int seed;
  double duration_s;
};

void runCase(const Case& c) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("offline-" + std::to_string(c.domain));
  const std::string scenario = std::string(NAVBUS_SOURCE_DIR) + "/sim/scenarios/" + c.scenario;
  const std::string filter_base = std::string(NAVBUS_SOURCE_DIR) + "/config/" + c.filter;
  const std::string domain = "domain_id: " + std::to_string(c.domain) + "\n";
  const std::string sim_cfg = test::writeFile(
      dir / "sim.yaml", "extends: " + scenario + "\n" + domain +
                            "timing: {duration_s: " + std::to_string(c.duration_s) + "}\n");
  // Every solution must reach the test even though the data runs through at full speed.
  const std::string filter_cfg = test::writeFile(
      dir / "filter.yaml", "extends: " + filter_base + "\n" + domain +
                               "solution_writer_profile: navbus_solution_writer_lossless\n" +
                               c.filter_extra);
  const std::string fm_cfg = test::writeFile(dir / "fm.yaml", domain);

  // Offline first: no DDS at all.
  test::ChildProcess offline(NAVBUS_TOOL_EXE,
                             {"offline", "--scenario", sim_cfg, "--filter", filter_cfg, "--seed",
                              std::to_string(c.seed), "-o", (dir / "offline").string()},
                             (dir / "offline.log").string());
  ASSERT_EQ(offline.wait(120s), 0) << test::readFile(dir / "offline.log");
  const std::vector<std::string> expected = readCsvRows(dir / "offline" / "solution.csv");
  ASSERT_GT(expected.size(), 100u);

  // The same over the bus: simulator, filter and fault manager as separate processes.
  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(c.domain, "offline-equals-bus"), shutdown);
  std::vector<std::string> rows;
  me.subscribe<NavigationSolutionPubSubType>(bus::topic::kNavSolution,
                                             bus::profile::kSolutionReader,
                                             [&](const NavigationSolution& s, const auto&) {
                                               if (s.mode() != MODE_INERTIAL_LOST)
                                                 rows.push_back(tool::csvRows(s).at(0));
                                             });
  test::ChildProcess filter(NAVBUS_FILTER_EXE, {"-c", filter_cfg}, (dir / "filter.log").string());
  test::ChildProcess fm(NAVBUS_FAULT_MANAGER_EXE, {"-c", fm_cfg}, (dir / "fm.log").string());
  test::ChildProcess sim(NAVBUS_SENSOR_SIM_EXE, {"-c", sim_cfg, "--seed", std::to_string(c.seed)},
                         (dir / "sim.log").string());
  // The simulator waits for the filter and the fault manager, publishes as fast as they take
  // it (reliable, nothing lost) and exits.
  while (sim.running()) me.spinOnce(50ms);
  EXPECT_EQ(sim.wait(1s), 0) << test::readFile(dir / "sim.log");
  test::spinUntil(me, 60s, [&] { return rows.size() >= expected.size(); });
  me.spinOnce(500ms);  // anything more that would arrive
  filter.signal(SIGTERM);
  fm.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  EXPECT_EQ(fm.wait(10s), 0);

  ASSERT_EQ(rows.size(), expected.size()) << test::readFile(dir / "filter.log");
  std::size_t differing = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i] != expected[i] && differing++ < 3) {
      ADD_FAILURE() << "solution " << i << " differs:\n bus:     " << rows[i]
                    << "\n offline: " << expected[i];
    }
  }
  EXPECT_EQ(differing, 0u);
  std::printf("%s: %zu solutions, bus and offline bit-identical (17-digit CSV rows): %s\n",
              c.scenario.c_str(), rows.size(), differing == 0 ? "yes" : "NO");
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}

}  // namespace

TEST(OfflineEqualsBus, LandVehicleMultiDimensionalFilter) {
  runCase({86, "seed004_land_vehicle.yaml", "filter_seed004_mdf.yaml", "", 5, 160.0});
}

TEST(OfflineEqualsBus, LeoFederatedGnssAndStarTracker) {
  runCase({87, "seed001_leo.yaml", "filter_seed001_lc.yaml", "fusion: federated\n", 3, 40.0});
}

// Run-time switching of the fusion structure by CMD_SELECT_FUSION (seed 001): centralized ->
// federated -> adaptive, and a structure that does not apply is refused (the solution keeps the
// last one).
TEST(FusionSwitch, SelectFusionCommandsTakeEffectOverTheBus) {
  constexpr int kDomain = 88;
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("fusion-switch");
  const std::string domain = "domain_id: " + std::to_string(kDomain) + "\n";
  const std::string sim_cfg = test::writeFile(
      dir / "sim.yaml", "extends: " + std::string(NAVBUS_SOURCE_DIR) +
                            "/sim/scenarios/seed001_leo.yaml\n" + domain +
                            "timing: {duration_s: 0, pacing: realtime,\n"
                            "  min_readers: {imu: 1, raw_imu: 0, gnss: 1, star_tracker: 1}}\n");
  const std::string filter_cfg =
      test::writeFile(dir / "filter.yaml", "extends: " + std::string(NAVBUS_SOURCE_DIR) +
                                               "/config/filter_seed001_lc.yaml\n" + domain);
  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "fusion-switch-test"), shutdown);
  std::vector<FusionStructure> seen;
  me.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) { seen.push_back(s.fusion()); });
  auto commands = me.createWriter<FilterCommandPubSubType>(bus::topic::kFilterCommand,
                                                           bus::profile::kDecisionWriter);
  test::ChildProcess filter(NAVBUS_FILTER_EXE, {"-c", filter_cfg}, (dir / "filter.log").string());
  test::ChildProcess sim(NAVBUS_SENSOR_SIM_EXE, {"-c", sim_cfg}, (dir / "sim.log").string());
  ASSERT_TRUE(test::spinUntil(me, 30s, [&] { return seen.size() >= 5; }))
      << test::readFile(dir / "filter.log");
  EXPECT_EQ(seen.back(), FUSION_CENTRALIZED);
  std::uint64_t id = 0;
  auto select = [&](FusionStructure f) {
    FilterCommand c;
    c.command_id(++id);
    c.vehicle_id(1);
    c.kind(CMD_SELECT_FUSION);
    c.fusion(f);
    c.issuer("fusion-switch-test");
    ASSERT_TRUE(commands.write(c));
  };
  for (FusionStructure f : {FUSION_FEDERATED, FUSION_ADAPTIVE}) {
    select(f);
    EXPECT_TRUE(test::spinUntil(me, 10s, [&] { return seen.back() == f; }))
        << "structure " << static_cast<int>(f) << " not reached";
  }
  select(FUSION_NONE);  // not a structure of a loosely coupled filter: refused
  const std::size_t before = seen.size();
  test::spinUntil(me, 10s, [&] { return seen.size() >= before + 10; });
  EXPECT_EQ(seen.back(), FUSION_ADAPTIVE);
  sim.signal(SIGTERM);
  filter.signal(SIGTERM);
  EXPECT_EQ(sim.wait(10s), 0);
  EXPECT_EQ(filter.wait(10s), 0);
  const std::string log = test::readFile(dir / "filter.log");
  EXPECT_NE(log.find("refused"), std::string::npos) << log;
  EXPECT_NE(log.find("commands applied 2 refused 1"), std::string::npos) << log;
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}
