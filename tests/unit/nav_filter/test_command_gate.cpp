// CommandGate: who may command navbus-filter and what, and the counts it keeps.
#include <gtest/gtest.h>

#include <cmath>

#include "navbus/nav_filter/command_gate.hpp"

namespace nb = navbus;
using nb::nav_filter::CommandGate;

namespace {

nb::nav_filter::FilterConfig gateConfig() {
  nb::nav_filter::FilterConfig c;
  c.command_issuers = {"fault-manager", "operator"};
  c.issuer_identities = {{"fault-manager", "navbus-fault-manager"},
                         {"operator", "navbus-operator"}};
  c.max_accel_compensation_mps2 = 0.5;
  c.max_gyro_compensation_radps = 1e-3;
  return c;
}

nb::FilterCommand relearn(double sigma) {
  nb::FilterCommand c;
  c.vehicle_id(1);
  c.issuer("fault-manager");
  c.kind(nb::CMD_RELEARN_BIAS);
  c.sensor(nb::SOURCE_GYRO);
  c.axis(1);
  c.bias_sigma(sigma);
  return c;
}

}  // namespace

TEST(CommandGate, RefusesIssuersNotConfiguredAndWritersNotTheirIdentity) {
  nb::bus::StreamCounters topic;
  CommandGate gate(gateConfig(), topic);
  nb::FilterCommand c = relearn(1e-4);
  EXPECT_TRUE(gate.authorized(c, std::nullopt));
  EXPECT_TRUE(gate.authorized(c, std::string("navbus-fault-manager")));
  EXPECT_FALSE(gate.authorized(c, std::string("navbus-operator")));  // impersonation
  c.issuer("somebody");
  EXPECT_FALSE(gate.authorized(c, std::nullopt));
  EXPECT_EQ(gate.counters().unauthorized, 1u);
  EXPECT_EQ(gate.counters().impersonated, 1u);
  EXPECT_EQ(gate.counters().refused, 2u);
  EXPECT_EQ(topic.rejected.at(nb::REJECT_UNAUTHORIZED), 2u);
  EXPECT_EQ(topic.accepted, 0u);
}

TEST(CommandGate, RefusesCommandsAboutDataBeforeTheFirstInput) {
  nb::bus::StreamCounters topic;
  CommandGate gate(gateConfig(), topic);
  nb::FilterCommand c = relearn(1e-4);
  c.time_gps_ns(1'000);
  EXPECT_TRUE(gate.refuseIfStale(c, -1));     // no input yet
  EXPECT_TRUE(gate.refuseIfStale(c, 2'000));  // before the first input
  EXPECT_FALSE(gate.refuseIfStale(c, 1'000));
  c.time_gps_ns(0);  // at once: never stale
  EXPECT_FALSE(gate.refuseIfStale(c, 2'000));
  EXPECT_EQ(gate.counters().stale, 2u);
  EXPECT_EQ(topic.rejected.at(nb::REJECT_STALE), 2u);
}

TEST(CommandGate, NamesTheFieldAndValueOutOfRange) {
  nb::bus::StreamCounters topic;
  CommandGate gate(gateConfig(), topic);
  nb::FilterCommand c = relearn(1e-4);
  c.axis(3);
  EXPECT_EQ(gate.check(c).value_or(""), "axis 3 outside 0..2");
  c = relearn(1e-4);
  c.kind(nb::CMD_COMPENSATE_BIAS);
  c.bias(2e-3);
  EXPECT_EQ(gate.check(c).value_or(""),
            "bias 0.002 outside +-0.001 (rad/s, max_gyro_compensation_deg_per_h)");
  c.kind(nb::CMD_EXCLUDE_SATELLITE);
  c.sv_id(33);
  EXPECT_EQ(gate.check(c).value_or(""), "sv_id 33 outside 1..32");
  c.sv_id(12);
  EXPECT_FALSE(gate.check(c).has_value());
}

TEST(CommandGate, CompensatesOnlyTheFusedReceiversClockNamingAnother) {
  // Given a filter fusing receiver 1's pseudoranges, a clock compensation for receiver 1 of
  // 299.8 km (1 ms) passes (a clock's jump has no IMU compensation limit), one for receiver 2
  // is refused naming both ids (taken when the filter fuses receiver 2 too), one not finite is
  // refused naming the field; a filter without pseudoranges refuses any.
  nb::bus::StreamCounters topic;
  nb::nav_filter::FilterConfig config = gateConfig();
  config.gnss_observations = nb::nav_filter::InputConfig{1, 1'000'000'000};
  CommandGate gate(config, topic);
  nb::FilterCommand c = relearn(0.0);
  c.kind(nb::CMD_COMPENSATE_BIAS);
  c.sensor(nb::SOURCE_RECEIVER_CLOCK);
  c.axis(0);
  c.sensor_id(1);
  c.bias(299792.458);
  c.bias_sigma(16.0);
  EXPECT_FALSE(gate.check(c).has_value()) << gate.check(c).value_or("");
  c.sensor_id(2);
  EXPECT_EQ(gate.check(c).value_or(""),
            "sensor_id 2 is not a receiver this filter fuses (gnss_observations.id 1)");
  // A filter fusing receiver 2 as well takes it, and still refuses receiver 3.
  config.second_gnss_receiver_id = 2;
  CommandGate both(config, topic);
  EXPECT_FALSE(both.check(c).has_value()) << both.check(c).value_or("");
  c.sensor_id(3);
  EXPECT_EQ(
      both.check(c).value_or(""),
      "sensor_id 3 is not a receiver this filter fuses (gnss_observations.id 1, second_id 2)");
  c.sensor_id(1);
  c.bias(std::nan(""));
  EXPECT_EQ(gate.check(c).value_or(""), "bias nan is not finite");
  c.bias(1.0);
  c.bias_sigma(-1.0);
  EXPECT_EQ(gate.check(c).value_or(""), "bias_sigma -1 outside 0..inf");
  CommandGate inertial(gateConfig(), topic);
  c.bias_sigma(1.0);
  EXPECT_EQ(inertial.check(c).value_or(""),
            "sensor_id 1: this filter fuses no receiver's pseudoranges");
}

TEST(CommandGate, ClampsARelearnSigmaToTheCompensationLimitAndCountsIt) {
  nb::bus::StreamCounters topic;
  CommandGate gate(gateConfig(), topic);
  EXPECT_FALSE(gate.check(relearn(5e-3)).has_value());  // a re-learn beyond the limit passes
  EXPECT_DOUBLE_EQ(gate.relearnSigma(relearn(5e-3)), 1e-3);
  EXPECT_DOUBLE_EQ(gate.relearnSigma(relearn(2e-4)), 2e-4);
  EXPECT_EQ(gate.counters().relearn_clamped, 1u);
  nb::FilterCommand compensate = relearn(5e-3);
  compensate.kind(nb::CMD_COMPENSATE_BIAS);  // a compensation beyond the limit does not
  EXPECT_EQ(gate.check(compensate).value_or(""), "bias_sigma 0.005 outside 0..0.001");
  gate.report(nb::FilterCommand{}, true);
  gate.report(nb::FilterCommand{}, false, nb::REJECT_OUT_OF_RANGE);
  EXPECT_EQ(topic.accepted, 1u);
  EXPECT_EQ(topic.rejected.at(nb::REJECT_OUT_OF_RANGE), 1u);
  EXPECT_EQ(gate.counters().applied, 1u);
  EXPECT_EQ(gate.counters().refused, 1u);
}

TEST(CommandGate, AnswersEachCommandsIssuerAppliedClampedOrRefusedWithTheFieldAndValue) {
  nb::bus::StreamCounters topic;
  std::vector<nb::FilterCommandOutcome> outcomes;
  CommandGate gate(gateConfig(), topic,
                   [&outcomes](const nb::FilterCommandOutcome& o) { outcomes.push_back(o); });
  nb::FilterCommand clamped = relearn(5e-3);
  clamped.command_id(7);
  clamped.run_id(42);
  gate.relearnSigma(clamped);  // applied at the limit
  gate.report(clamped, true);
  nb::FilterCommand applied = relearn(2e-4);
  applied.command_id(8);
  gate.relearnSigma(applied);
  // The pipeline prepares the refusal's words before it knows: an applied command drops them.
  gate.report(applied, true, nb::REJECT_NOT_APPLICABLE, "not available in the configured mode");
  nb::FilterCommand stale = relearn(2e-4);
  stale.command_id(9);
  stale.time_gps_ns(1'000);
  EXPECT_TRUE(gate.refuseIfStale(stale, 2'000));
  ASSERT_EQ(outcomes.size(), 3u);
  EXPECT_EQ(outcomes[0].command_id(), 7u);
  EXPECT_EQ(outcomes[0].run_id(), 42u);
  EXPECT_EQ(outcomes[0].issuer(), "fault-manager");
  EXPECT_EQ(outcomes[0].outcome(), nb::OUTCOME_CLAMPED);
  EXPECT_EQ(outcomes[0].detail(), "bias_sigma 0.005 clamped to the compensation limit 0.001");
  EXPECT_EQ(outcomes[1].outcome(), nb::OUTCOME_APPLIED);
  EXPECT_EQ(outcomes[1].detail(), "");
  EXPECT_EQ(outcomes[2].outcome(), nb::OUTCOME_REFUSED);
  EXPECT_EQ(outcomes[2].reason(), nb::REJECT_STALE);
  EXPECT_NE(outcomes[2].detail().to_string().find("before this run's first input"),
            std::string::npos);
}
