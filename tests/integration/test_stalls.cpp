// The filter process stopped (SIGSTOP, as a debugger, a page-fault storm or VM steal time
// would) or starved of CPU while the simulator publishes as fast as the readers take: no
// increment is refused as late, every solution time is published once, and every solution
// equals `navbus offline`'s (fault-free seed-000 flight, tightly coupled, with the fault
// manager). docs/architecture.md, the ordered merge.
#include <csignal>
#include <map>

#include <gtest/gtest.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "harness.hpp"
#include "navbus/records/formatters.hpp"

using namespace navbus;
using namespace std::chrono_literals;

namespace {

enum class Disturbance { kStops, kCpuHogs };

void runWith(int domain, Disturbance disturbance) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("stalls-" + std::to_string(domain));
  const test::Seed000Loop cfg =
      test::writeSeed000Loop(dir, domain, "timing: {duration_s: 300, pacing: fast}\n");
  const std::string& sim_cfg = cfg.sim;
  const std::string& filter_cfg = cfg.filter;
  const std::string& fm_cfg = cfg.fault_manager;
  ASSERT_EQ(test::runOffline(cfg, dir, "3"), 0) << test::readFile(dir / "offline.log");
  const std::vector<std::string> expected = test::csvDataRows(dir / "offline" / "solution.csv");
  ASSERT_GT(expected.size(), 2000u);

  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(domain, "stalls"), shutdown);
  std::map<std::uint64_t, int> published;  // solution time -> how many times
  std::vector<std::string> rows;
  me.subscribe<NavigationSolutionPubSubType>(bus::topic::kNavSolution,
                                             bus::profile::kSolutionReader,
                                             [&](const NavigationSolution& s, const auto&) {
                                               if (++published[s.time_gps_ns()] == 1)
                                                 rows.push_back(records::csvRows(s).at(0));
                                             });
  test::ChildProcess filter(NAVBUS_FILTER_EXE, {"-c", filter_cfg}, (dir / "filter.log").string());
  test::ChildProcess fm(NAVBUS_FAULT_MANAGER_EXE, {"-c", fm_cfg}, (dir / "fm.log").string());
  std::vector<std::unique_ptr<test::ChildProcess>> hogs;
  if (disturbance == Disturbance::kCpuHogs) {
    for (int k = 0; k < 2; ++k)
      hogs.push_back(std::make_unique<test::ChildProcess>(
          "/bin/sh", std::vector<std::string>{"-c", "while :; do :; done"}, "/dev/null"));
  }
  test::ChildProcess sim(NAVBUS_SENSOR_SIM_EXE, {"-c", sim_cfg, "--seed", "3"},
                         (dir / "sim.log").string());
  if (disturbance == Disturbance::kStops) {
    // Stopped twice for 1.5 s while the data flows (a third of the way and two thirds in).
    for (const std::size_t at : {expected.size() / 3, 2 * expected.size() / 3}) {
      ASSERT_TRUE(test::spinUntil(me, 120s, [&] { return rows.size() >= at; }));
      filter.signal(SIGSTOP);
      const auto until = std::chrono::steady_clock::now() + 1500ms;
      while (std::chrono::steady_clock::now() < until) me.spinOnce(50ms);
      filter.signal(SIGCONT);
    }
  }
  while (sim.running()) me.spinOnce(50ms);
  EXPECT_EQ(sim.wait(1s), 0) << test::readFile(dir / "sim.log");
  test::spinUntil(me, 60s, [&] { return rows.size() >= expected.size(); });
  me.spinOnce(500ms);
  hogs.clear();
  filter.signal(SIGTERM);
  fm.signal(SIGTERM);
  EXPECT_EQ(filter.wait(10s), 0);
  EXPECT_EQ(fm.wait(10s), 0);

  const std::string log = test::readFile(dir / "filter.log");
  EXPECT_EQ(log.find("rejected sample"), std::string::npos) << "nothing refused: " << log;
  EXPECT_NE(log.find("late samples merged by rewinding"), std::string::npos) << log;
  if (disturbance == Disturbance::kStops) {
    EXPECT_NE(log.find("stalls of the filter process"), std::string::npos) << log;
  }
  int repeated = 0;
  for (const auto& [time, n] : published) repeated += n > 1 ? 1 : 0;
  EXPECT_EQ(repeated, 0) << "each solution time once";
  ASSERT_EQ(rows.size(), expected.size()) << log;
  const std::size_t differing = test::countDiffering(rows, expected);
  EXPECT_EQ(differing, 0u);
  std::printf(
      "%s: %zu solutions, %zu differ from offline\n",
      disturbance == Disturbance::kStops ? "filter stopped twice for 1.5 s" : "two CPU hogs",
      rows.size(), differing);
  test::cleanSharedMemory();
  std::filesystem::remove_all(dir);
}

}  // namespace

TEST(Stalls, FilterStoppedTwiceEqualsOfflineOnEverySolution) {
  runWith(102, Disturbance::kStops);
}

TEST(Stalls, TwoCpuHogsEqualOfflineOnEverySolution) {
  runWith(103, Disturbance::kCpuHogs);
}
