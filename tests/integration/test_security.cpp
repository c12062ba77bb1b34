// DDS Security (secure participant profile, credentials made by scripts/make_credentials.sh at
// build time). navbus-filter runs secure with the filter identity; the test feeds it sensor
// data as the simulator identity and reads its solutions as the tool identity. Beside them:
//  - an intruder without credentials (the plain loopback profile) writes a plausible bias
//    compensation "from the fault manager", a stream-lost decision and pseudoranges with the
//    configured receiver id, and reads solutions;
//  - an inertial unit (imu-sensor identity) and the simulator identity try to write what their
//    grants do not allow: commands, decisions, pseudoranges, and to read solutions.
//  - the operator identity sends a command claiming to come from the fault manager (refused:
//    the issuer is not the identity that wrote it) and one as itself (applied).
// Nothing of the intruder reaches the filter (no command, no decision, not one epoch more
// than the simulator sent) and it reads nothing; the wrong roles cannot even create the
// writers and readers (Fast DDS's access control refuses them locally, and remote
// participants check the same signed permissions).
#include <algorithm>
#include <cmath>
#include <regex>

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

constexpr int kDomain = 91;
constexpr const char* kSecureProfile = "navbus_participant_udp_loopback_secure";

std::string identity(const std::string& name) {
  return std::string(navbus::test_paths::credentialsDir()) + "/" + name;
}

bus::Participant::Options secureParticipant(const std::string& name, const std::string& id) {
  auto o = test::testParticipant(kDomain, name);
  o.dds.participant_profile = kSecureProfile;
  o.dds.security_identity = identity(id);
  return o;
}

FilterCommand forgedCompensation() {
  FilterCommand c;
  c.command_id(1);
  c.vehicle_id(1);
  c.kind(CMD_COMPENSATE_BIAS);
  c.sensor(SOURCE_ACCELEROMETER);
  c.axis(0);
  c.bias(0.5);  // [m/s^2]: plausible for a failed accelerometer, disastrous if applied
  c.issuer("fault-manager");
  return c;
}

FaultDecision forgedStreamLost() {
  FaultDecision d;
  d.decision_id(1);
  d.event(EVENT_STREAM_LOST);
  d.source(SOURCE_IMU_STREAM);
  d.sensor_id(1);
  d.detector("watchdog");
  return d;
}

/// The number after `label` in the filter's summary line (-1 if absent).
long summaryCount(const std::string& log, const std::string& label) {
  std::smatch m;
  if (!std::regex_search(log, m, std::regex(label + " ([0-9]+)"))) return -1;
  return std::stol(m[1]);
}

}  // namespace

TEST(Security, WrongRolesCannotCreateWhatTheirGrantsDeny) {
  bus::ShutdownSignal shutdown;
  bus::Participant imu_unit(secureParticipant("imu-unit", "imu-sensor"), shutdown);
  // The positive control: what the grant allows can be created.
  EXPECT_NO_THROW(imu_unit.createWriter<ImuIncrementPubSubType>(bus::topic::kImuIncrement,
                                                                bus::profile::kSensorWriter));
  EXPECT_THROW(imu_unit.createWriter<FilterCommandPubSubType>(bus::topic::kFilterCommand,
                                                              bus::profile::kDecisionWriter),
               bus::DdsError);
  EXPECT_THROW(imu_unit.createWriter<FaultDecisionPubSubType>(bus::topic::kFaultDecision,
                                                              bus::profile::kDecisionWriter),
               bus::DdsError);
  EXPECT_THROW(imu_unit.createWriter<GnssObservationEpochPubSubType>(
                   bus::topic::kGnssObservations, bus::profile::kMeasurementWriter),
               bus::DdsError);
  EXPECT_THROW(imu_unit.subscribe<NavigationSolutionPubSubType>(
                   bus::topic::kNavSolution, bus::profile::kSolutionReader,
                   [](const NavigationSolution&, const auto&) {}),
               bus::DdsError);

  bus::Participant simulator(secureParticipant("simulator", "simulator"), shutdown);
  EXPECT_NO_THROW(simulator.createWriter<GnssObservationEpochPubSubType>(
      bus::topic::kGnssObservations, bus::profile::kMeasurementWriter));
  EXPECT_THROW(simulator.createWriter<FilterCommandPubSubType>(bus::topic::kFilterCommand,
                                                               bus::profile::kDecisionWriter),
               bus::DdsError);
  EXPECT_THROW(simulator.createWriter<FaultDecisionPubSubType>(bus::topic::kFaultDecision,
                                                               bus::profile::kDecisionWriter),
               bus::DdsError);
  EXPECT_THROW(simulator.subscribe<FaultDecisionPubSubType>(
                   bus::topic::kFaultDecision, bus::profile::kDecisionReader,
                   [](const FaultDecision&, const auto&) {}),
               bus::DdsError);
}

TEST(Security, ParticipantWithoutCredentialsGetsNothingAcceptedAndReadsNothing) {
  test::cleanSharedMemory();
  const auto dir = test::scratchDir("security");
  const std::string cfg = test::writeFile(
      dir / "filter.yaml", test::filterConfig(kDomain) +
                               "mode: tightly_coupled\nparticipant_profile: " + kSecureProfile +
                               "\nsecurity_identity: " + identity("filter") + "\n");
  test::ChildProcess filter(navbus::test_paths::filterExe(), {"-c", cfg},
                            (dir / "filter.log").string());

  bus::ShutdownSignal shutdown;
  bus::Participant sensors(secureParticipant("sensors", "simulator"), shutdown);
  bus::Participant observer(secureParticipant("observer", "tool"), shutdown);
  bus::Participant intruder(test::testParticipant(kDomain, "intruder"), shutdown);

  std::vector<NavigationSolution> solutions;
  observer.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution& s, const auto&) { solutions.push_back(s); });
  Health filter_health;
  std::vector<ParticipantState> states;  // the filter's reported states, in order
  observer.subscribe<HealthPubSubType>(bus::topic::kHealth, bus::profile::kHealthReader,
                                       [&](const Health& h, const auto&) {
                                         if (h.participant().to_string() != "navbus-filter") return;
                                         filter_health = h;
                                         states.push_back(h.state());
                                       });
  std::size_t intruder_read = 0;
  intruder.subscribe<NavigationSolutionPubSubType>(
      bus::topic::kNavSolution, bus::profile::kSolutionReader,
      [&](const NavigationSolution&, const auto&) { ++intruder_read; });
  auto command = intruder.createWriter<FilterCommandPubSubType>(bus::topic::kFilterCommand,
                                                                bus::profile::kDecisionWriter);
  auto decision = intruder.createWriter<FaultDecisionPubSubType>(bus::topic::kFaultDecision,
                                                                 bus::profile::kDecisionWriter);
  auto fake_obs = intruder.createWriter<GnssObservationEpochPubSubType>(
      bus::topic::kGnssObservations, bus::profile::kMeasurementWriter);

  bus::Participant console(secureParticipant("console", "operator"), shutdown);
  auto operator_command = console.createWriter<FilterCommandPubSubType>(
      bus::topic::kFilterCommand, bus::profile::kDecisionWriter);

  test::SensorInputWriters w(sensors);
  auto spinAll = [&] {
    sensors.spinOnce(1ms);
    observer.spinOnce(1ms);
    intruder.spinOnce(1ms);
    console.spinOnce(1ms);
  };
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!(w.matched() && filter_health.inputs().size() > 0 &&
           operator_command.matchedReaders() > 0) &&
         std::chrono::steady_clock::now() < deadline)
    spinAll();
  ASSERT_GT(operator_command.matchedReaders(), 0u);
  ASSERT_TRUE(w.matched()) << "the secure filter did not match the simulator identity\n"
                           << test::readFile(dir / "filter.log");
  EXPECT_EQ(command.matchedReaders(), 0u);
  EXPECT_EQ(decision.matchedReaders(), 0u);
  EXPECT_EQ(fake_obs.matchedReaders(), 0u);

  sim::ScenarioSource src = test::testScenarioSource();
  std::uint64_t seq = 0, n_obs = 0, n_fix = 0, n_star = 0, n_forged = 0;
  for (int k = 0; k < 500; ++k) {
    const sim::SensorFrame f = src.next();
    w.imu.write(bus::toIdl(f.increment, 1, ++seq));
    if (f.has_gnss) {
      auto e = sensor_sim::toIdl(f.gnss, 1, ++n_obs);
      w.obs.write(e);
      w.fix.write(sensor_sim::toIdl(f.fix, 1, ++n_fix));
      // The intruder: the same epoch 300 m off on every satellite, a compensation and a loss.
      for (auto& s : e.satellites()) s.pseudorange_m(s.pseudorange_m() + 300.0);
      fake_obs.write(e);
      auto c = forgedCompensation();
      c.command_id(++n_forged);
      c.time_gps_ns(e.time_gps_ns());
      command.write(c);
      auto d = forgedStreamLost();
      d.decision_id(static_cast<std::uint32_t>(n_forged));
      d.time_gps_ns(e.time_gps_ns());
      decision.write(d);
      if (n_obs == 2) {
        auto impersonated = forgedCompensation();  // "fault-manager", written by the operator
        impersonated.command_id(100);
        impersonated.time_gps_ns(e.time_gps_ns());
        operator_command.write(impersonated);
        FilterCommand own;  // as itself: expect the IMU stream (a no-op while it flows)
        own.command_id(101);
        own.vehicle_id(1);
        own.kind(CMD_READMIT_STREAM);
        own.sensor(SOURCE_IMU_STREAM);
        own.sensor_id(1);
        own.time_gps_ns(e.time_gps_ns());
        own.issuer("operator");
        operator_command.write(own);
      }
    }
    if (f.has_star_tracker) w.star.write(sensor_sim::toIdl(f.star_tracker, 1, ++n_star));
    spinAll();
  }
  ASSERT_GT(n_forged, 3u);

  auto obsStream = [&]() -> const StreamHealth* {
    for (const auto& in : filter_health.inputs())
      if (in.topic().to_string() == bus::topic::kGnssObservations) return &in;
    return nullptr;
  };
  const auto until = std::chrono::steady_clock::now() + 20s;
  while (!(obsStream() != nullptr && obsStream()->received() >= n_obs && solutions.size() >= 40) &&
         std::chrono::steady_clock::now() < until)
    spinAll();
  const auto* obs = obsStream();
  ASSERT_NE(obs, nullptr) << test::readFile(dir / "filter.log");
  // Exactly the simulator's epochs: none of the intruder's reached the filter.
  EXPECT_EQ(obs->received(), n_obs);
  EXPECT_EQ(obs->accepted(), n_obs);
  ASSERT_GE(solutions.size(), 40u);
  // Inertial only until the first epoch, then tightly coupled: never INERTIAL_LOST (the forged
  // decision) and no fault flag (the forged compensation).
  for (const auto& s : solutions) {
    EXPECT_TRUE(s.mode() == MODE_INERTIAL_ONLY || s.mode() == MODE_TIGHTLY_COUPLED) << s.mode();
    EXPECT_EQ(s.active_fault_flags(), 0u) << "a forged command or decision took effect";
  }
  EXPECT_EQ(solutions.back().mode(), MODE_TIGHTLY_COUPLED);
  EXPECT_EQ(intruder_read, 0u) << "a participant without credentials read solutions";
  // The operator's two commands in the filter's health: one accepted, one unauthorized.
  const StreamHealth* cmd = nullptr;
  for (const auto& in : filter_health.inputs())
    if (in.topic().to_string() == bus::topic::kFilterCommand) cmd = &in;
  ASSERT_NE(cmd, nullptr);
  EXPECT_EQ(cmd->received(), 2u);
  EXPECT_EQ(cmd->accepted(), 1u);
  ASSERT_EQ(cmd->rejected().size(), 1u);
  EXPECT_EQ(cmd->rejected()[0].reason(), REJECT_UNAUTHORIZED);
  EXPECT_EQ(cmd->rejected()[0].count(), 1u);
  // Health: STARTING before the first solution, RUNNING while solutions flow, and no longer
  // RUNNING once they stop (the data ended): DEGRADED within 1 s plus a health period.
  ASSERT_FALSE(states.empty());
  EXPECT_EQ(states.front(), STATE_STARTING);
  EXPECT_NE(std::find(states.begin(), states.end(), STATE_RUNNING), states.end());
  const auto stopped = std::chrono::steady_clock::now() + 4s;
  while (states.back() != STATE_DEGRADED && std::chrono::steady_clock::now() < stopped) spinAll();
  EXPECT_EQ(states.back(), STATE_DEGRADED)
      << "health says " << states.back() << " while the filter produces nothing";

  filter.signal(SIGTERM);
  ASSERT_EQ(filter.wait(10s), std::optional<int>(0));
  const std::string log = test::readFile(dir / "filter.log");
  EXPECT_EQ(summaryCount(log, "decisions seen"), 0) << log;
  EXPECT_EQ(summaryCount(log, "commands applied"), 1) << log;  // the operator's own
  EXPECT_EQ(summaryCount(log, "commands applied [0-9]+ refused"), 1) << log;
  EXPECT_EQ(summaryCount(log, "issuer not the writer's identity"), 1) << log;
  EXPECT_EQ(summaryCount(log, "unauthorized issuer"), 0) << log;
  std::printf(
      "intruder wrote %llu commands, %llu decisions, %llu pseudorange epochs: 0 accepted; "
      "filter fused %llu genuine epochs, %zu solutions, intruder read 0\n",
      static_cast<unsigned long long>(n_forged), static_cast<unsigned long long>(n_forged),
      static_cast<unsigned long long>(n_forged), static_cast<unsigned long long>(n_obs),
      solutions.size());
  test::cleanSharedMemory();
}
