// fault_monitor.judged_from_start: the filter subscribes to its inputs only once its fault
// monitor is connected (the monitor's progress writer and its reader of the diagnostics both
// matched), so that a replay as fast as the readers take it cannot start before the monitor
// reads the first diagnostics epoch. The test participant plays the sensor and the monitor:
// its IMU writer sees the filter's reader only after it has created both monitor endpoints.
// Domain 189.
#include <gtest/gtest.h>
#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/HealthPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "harness.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace std::chrono_literals;

namespace {
constexpr int kDomain = 189;

/// Spins `me` for `duration`; false if `imu` matched a reader meanwhile.
bool noReaderFor(bus::Participant& me, const bus::Writer<ImuIncrement>& imu,
                 std::chrono::milliseconds duration) {
  return !test::spinUntil(me, duration, [&] { return imu.matchedReaders() > 0; });
}
}  // namespace

TEST(MonitorGate, JudgedFromStartTakesNoInputBeforeTheMonitorsProgressAndDiagnosticsEndpoints) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("monitor-gate");
  const std::string filter_cfg = test::writeFile(
      dir / "filter.yaml", test::filterConfig(kDomain) +
                               "mode: tightly_coupled\n"
                               "fault_monitor: {participant: navbus-fault-manager, timeout_s: 3.0, "
                               "judgement_wait_s: 60, judged_from_start: true}\n");
  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "monitor-gate-test"), shutdown);
  bool filter_seen = false;
  me.subscribe<HealthPubSubType>(bus::topic::kHealth, bus::profile::kHealthReader,
                                 [&](const Health& h, const auto&) {
                                   if (h.participant().to_string() == "navbus-filter")
                                     filter_seen = true;
                                 });
  auto imu = me.createWriter<ImuIncrementPubSubType>(bus::topic::kImuIncrement,
                                                     bus::profile::kSensorWriter);
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", filter_cfg},
                            (dir / "filter.log").string());
  // Discovered (its health reaches us), yet no input reader: no monitor is connected.
  ASSERT_TRUE(test::spinUntil(me, 20s, [&] { return filter_seen; }))
      << test::readFile(dir / "filter.log");
  EXPECT_TRUE(noReaderFor(me, imu, 1500ms)) << "the filter took inputs without its monitor";

  // The monitor's progress writer alone: a monitor whose GLR does not read the diagnostics yet
  // would miss the first epochs, so the gate stays shut.
  auto progress = me.createWriter<FaultMonitorProgressPubSubType>(bus::topic::kFaultProgress,
                                                                  bus::profile::kProgressWriter);
  EXPECT_TRUE(noReaderFor(me, imu, 1500ms)) << "the filter took inputs before the diagnostics "
                                               "had a reader";

  // And its reader of the diagnostics: the filter subscribes to its inputs.
  me.subscribe<FilterDiagnosticsPubSubType>(bus::topic::kFilterDiagnostics,
                                            bus::profile::kDiagnosticsReader,
                                            [](const auto&, const auto&) {});
  EXPECT_TRUE(test::spinUntil(me, 10s, [&] { return imu.matchedReaders() > 0; }))
      << "the filter did not take its inputs once the monitor was connected\n"
      << test::readFile(dir / "filter.log");
  EXPECT_EQ(progress.matchedReaders(), 1u);
  filter.signal(SIGTERM);
  EXPECT_EQ(filter.wait(15s), 0);
  const std::string log = test::readFile(dir / "filter.log");
  EXPECT_NE(log.find("fault monitor connected after"), std::string::npos) << log;
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}
