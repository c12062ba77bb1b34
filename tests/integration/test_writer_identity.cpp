// A second writer on a configured sensor key: while the simulator publishes receiver 1's
// epochs, another participant publishes epochs of receiver 1 too (300 m off on every satellite,
// the same sequence numbers and times). navbus-filter keeps them out and counts them
// (second_writer) while fusing every genuine epoch; navbus-fault-manager publishes one fault
// decision naming the stream (detector "writer-identity").
#include <gtest/gtest.h>
#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/HealthPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>

#include "harness.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sim/scenario_source.hpp"
#include "test_paths.hpp"

using namespace navbus;
using namespace std::chrono_literals;

namespace {
constexpr int kDomain = 93;
}  // namespace

TEST(WriterIdentity, SecondWriterOnASensorKeyIsKeptOutAndReported) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("writer-identity");
  const std::string cfg =
      test::writeFile(dir / "filter.yaml", test::filterConfig(kDomain) + "mode: tightly_coupled\n");
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", cfg},
                            (dir / "filter.log").string());
  test::ChildProcess fm(navbus::test_paths::faultManagerExe(),
                        {"-c", std::string(navbus::test_paths::configDir()) + "/fault_manager.yaml",
                         "-d", std::to_string(kDomain)},
                        (dir / "fm.log").string());

  bus::ShutdownSignal shutdown;
  bus::Participant me(test::testParticipant(kDomain, "writer-identity-test"), shutdown);
  bus::Participant impostor(test::testParticipant(kDomain, "impostor"), shutdown);
  std::vector<NavigationSolution> solutions;
  me.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) { solutions.push_back(s); });
  std::vector<FaultDecision> identity_decisions;
  me.subscribe<FaultDecisionPubSubType>(bus::topic::kFaultDecision, bus::profile::kDecisionReader,
                                        [&](const FaultDecision& d, const auto&) {
                                          if (d.detector().to_string() == "writer-identity")
                                            identity_decisions.push_back(d);
                                        });
  Health filter_health;
  me.subscribe<HealthPubSubType>(bus::topic::kHealth, bus::profile::kHealthReader,
                                 [&](const Health& h, const auto&) {
                                   if (h.participant().to_string() == "navbus-filter")
                                     filter_health = h;
                                 });
  test::SensorInputWriters w(me);
  auto second = impostor.createWriter<GnssObservationEpochPubSubType>(
      bus::topic::kGnssObservations, bus::profile::kMeasurementWriter);
  auto spinBoth = [&] {
    me.spinOnce(1ms);
    impostor.spinOnce(1ms);
  };
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!(w.matched() && second.matchedReaders() >= 2) &&
         std::chrono::steady_clock::now() < deadline)
    spinBoth();
  ASSERT_TRUE(w.matched());
  ASSERT_GE(second.matchedReaders(), 2u) << "filter and fault manager";

  sim::ScenarioSource src = test::testScenarioSource();
  std::uint64_t seq = 0, n_obs = 0, n_fix = 0, n_star = 0, n_second = 0;
  for (int k = 0; k < 600; ++k) {
    const sim::SensorFrame f = src.next();
    w.imu.write(bus::toIdl(f.increment, 1, ++seq));
    if (f.has_gnss) {
      auto e = sensor_sim::toIdl(f.gnss, 1, ++n_obs);
      w.obs.write(e);
      w.fix.write(sensor_sim::toIdl(f.fix, 1, ++n_fix));
      if (n_obs >= 2) {  // the genuine writer owns receiver 1 by then
        for (auto& s : e.satellites()) s.pseudorange_m(s.pseudorange_m() + 300.0);
        second.write(e);
        ++n_second;
      }
    }
    if (f.has_star_tracker) w.star.write(sensor_sim::toIdl(f.star_tracker, 1, ++n_star));
    spinBoth();
  }
  auto obsStream = [&]() -> const StreamHealth* {
    for (const auto& in : filter_health.inputs())
      if (in.topic().to_string() == bus::topic::kGnssObservations) return &in;
    return nullptr;
  };
  auto secondWriterRejections = [&]() -> std::uint64_t {
    const auto* s = obsStream();
    if (s == nullptr) return 0;
    for (const auto& r : s->rejected())
      if (r.reason() == REJECT_SECOND_WRITER) return r.count();
    return 0;
  };
  const auto until = std::chrono::steady_clock::now() + 20s;
  while (!(secondWriterRejections() == n_second && obsStream()->accepted() == n_obs &&
           !identity_decisions.empty() && solutions.size() >= 50) &&
         std::chrono::steady_clock::now() < until)
    spinBoth();
  ASSERT_NE(obsStream(), nullptr) << test::readFile(dir / "filter.log");
  EXPECT_EQ(secondWriterRejections(), n_second) << test::readFile(dir / "filter.log");
  EXPECT_EQ(obsStream()->accepted(), n_obs);
  EXPECT_EQ(obsStream()->received(), n_obs + n_second);
  ASSERT_EQ(identity_decisions.size(), 1u) << test::readFile(dir / "fm.log");
  const FaultDecision& d = identity_decisions.front();
  EXPECT_EQ(d.event(), EVENT_FAULT_DETECTED);
  EXPECT_EQ(d.source(), SOURCE_GNSS_OBS_STREAM);
  EXPECT_EQ(d.sensor_id(), 1u);
  // Tightly coupled on the genuine epochs, no fault flag (the 300 m would have raised the GLR).
  // (Once the test stops sending, the watchdog's stream-lost decisions are expected.)
  std::size_t coupled = 0;
  for (const auto& s : solutions) {
    if (s.mode() != MODE_TIGHTLY_COUPLED) continue;
    ++coupled;
    EXPECT_EQ(s.active_fault_flags(), 0u);
  }
  EXPECT_GE(coupled, 40u);
  std::printf(
      "second writer on receiver 1: %llu epochs written, %llu rejected (second_writer), %llu "
      "genuine accepted; decision %u from the fault manager\n",
      static_cast<unsigned long long>(n_second),
      static_cast<unsigned long long>(secondWriterRejections()),
      static_cast<unsigned long long>(obsStream()->accepted()), d.decision_id());
  test::cleanSharedMemory();
}
