// The channels in Foxglove's schemas that `navbus foxglove` and `navbus record --foxglove` derive
// from navbus samples: the solution as foxglove.LocationFix (degrees, the covariance turned from
// N E D sigmas into East, North, Up), decisions, commands and outcomes as foxglove.Log lines.
#include <gtest/gtest.h>

#include <navbus_idl/Health.h>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "navbus/bus/gps_time.hpp"
#include "navbus/tool/foxglove_channels.hpp"

namespace {

using navbus::tool::DerivedChannel;
using navbus::tool::derivedMessage;
using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;
constexpr std::uint64_t kReceivedUnixNs = 1'790'000'000'123'456'789ULL;

json parsed(const navbus::tool::DerivedMessage& m) {
  return json::parse(m.json.begin(), m.json.end());
}

navbus::NavigationSolution solutionAt(double lat_deg, double lon_deg) {
  navbus::NavigationSolution s;
  s.vehicle_id(3);
  s.time_gps_ns(navbus::bus::unixToGpsNs(1'767'225'600ULL * navbus::bus::kNsPerSecond));
  s.latitude_rad(lat_deg * kPi / 180.0);
  s.longitude_rad(lon_deg * kPi / 180.0);
  s.height_m(123.5);
  s.pos_sigma_ned_m({1.0, 2.0, 3.0});
  s.vel_ned_mps({4.0, 5.0, 6.0});
  s.yaw_rad(0.25);
  s.covariance_valid(true);
  s.output(navbus::OUTPUT_DETERMINISTIC);
  return s;
}

}  // namespace

TEST(GpsTime, UnixAndGpsDifferByTheEpochAndTheLeapSeconds) {
  // 2026-01-01 00:00:00 UTC is Unix 1767225600 s, GPS 1451260818 s (18 leap seconds).
  EXPECT_EQ(navbus::bus::unixToGpsNs(1'767'225'600ULL * navbus::bus::kNsPerSecond),
            1'451'260'818ULL * navbus::bus::kNsPerSecond);
  EXPECT_EQ(navbus::bus::gpsToUnixNs(1'451'260'818ULL * navbus::bus::kNsPerSecond + 7),
            1'767'225'600ULL * navbus::bus::kNsPerSecond + 7);
}

TEST(FoxgloveChannels, SolutionIsALocationFixInDegreesWithAnEnuCovariance) {
  const auto m = derivedMessage(solutionAt(48.5, -2.25), kReceivedUnixNs);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->channel, DerivedChannel::kLocationFix);
  const json j = parsed(*m);
  EXPECT_NEAR(j["latitude"].get<double>(), 48.5, 1e-12);
  EXPECT_NEAR(j["longitude"].get<double>(), -2.25, 1e-12);
  EXPECT_EQ(j["altitude"].get<double>(), 123.5);
  // sigma N 1, E 2, D 3 -> East 4, North 1, Up 9 on the diagonal.
  EXPECT_EQ(j["position_covariance"], json::array({4.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 9.0}));
  EXPECT_EQ(j["position_covariance_type"].get<int>(), 2);                   // DIAGONAL_KNOWN
  EXPECT_EQ(j["timestamp"]["sec"].get<std::uint64_t>(), 1'767'225'600ULL);  // validity, UTC
  EXPECT_EQ(j["timestamp"]["nsec"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(j["frame_id"].get<std::string>(), "vehicle_3");
  EXPECT_EQ(j["heading"].get<double>(), 0.25);
  EXPECT_EQ(j["velocity"], (json{{"x", 5.0}, {"y", 4.0}, {"z", -6.0}}));  // E N U
}

TEST(FoxgloveChannels, InvalidCovarianceIsUnknownAndLowLatencyDerivesNothing) {
  navbus::NavigationSolution s = solutionAt(10.0, 20.0);
  s.covariance_valid(false);
  const json j = parsed(*derivedMessage(s, kReceivedUnixNs));
  EXPECT_EQ(j["position_covariance_type"].get<int>(), 0);
  EXPECT_EQ(j["position_covariance"], json::array({0, 0, 0, 0, 0, 0, 0, 0, 0}));
  s.output(navbus::OUTPUT_LOW_LATENCY);
  EXPECT_FALSE(derivedMessage(s, kReceivedUnixNs).has_value());
  EXPECT_FALSE(derivedMessage(navbus::Health{}, kReceivedUnixNs).has_value());
}

TEST(FoxgloveChannels, NonFiniteNumbersAreNullNotAnException) {
  navbus::NavigationSolution s = solutionAt(10.0, 20.0);
  s.height_m(std::numeric_limits<double>::quiet_NaN());
  const json j = parsed(*derivedMessage(s, kReceivedUnixNs));
  EXPECT_TRUE(j["altitude"].is_null());
}

TEST(FoxgloveChannels, DecisionIsAWarningLogLineNamingTheSatellite) {
  navbus::FaultDecision d;
  d.decision_id(7);
  d.time_gps_ns(2200ULL * 604'800ULL * navbus::bus::kNsPerSecond + 1'500'000'000ULL);
  d.event(navbus::EVENT_FAULT_DETECTED);
  d.source(navbus::SOURCE_SATELLITE);
  d.sv_id(23);
  d.shape(navbus::SHAPE_RAMP);
  d.test_statistic(41.5);
  d.threshold(20.25);
  d.magnitude(0.5);
  d.detector("glr");
  const auto m = derivedMessage(d, kReceivedUnixNs);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->channel, DerivedChannel::kLog);
  const json j = parsed(*m);
  EXPECT_EQ(j["level"].get<int>(), 3);  // WARNING
  EXPECT_EQ(j["name"].get<std::string>(), "fault/glr");
  const std::string text = j["message"].get<std::string>();
  EXPECT_NE(text.find("decision 7 at GPS 2200/1.500: FAULT_DETECTED SATELLITE G23"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("statistic 41.5 against 20.25, RAMP of 0.5"), std::string::npos) << text;
  EXPECT_EQ(j["timestamp"]["sec"].get<std::uint64_t>(), 1'790'000'000ULL);  // reception
  EXPECT_EQ(j["timestamp"]["nsec"].get<std::uint64_t>(), 123'456'789ULL);
  d.event(navbus::EVENT_FAULT_CLEARED);
  EXPECT_EQ(parsed(*derivedMessage(d, kReceivedUnixNs))["level"].get<int>(), 2);  // INFO
}

TEST(FoxgloveChannels, CommandsAndOutcomesAreLogLinesWithTheirLevels) {
  navbus::FilterCommand c;
  c.command_id(4);
  c.vehicle_id(1);
  c.kind(navbus::CMD_EXCLUDE_SATELLITE);
  c.sv_id(5);
  c.decision_id(7);
  c.issuer("fault-manager");
  json j = parsed(*derivedMessage(c, kReceivedUnixNs));
  EXPECT_EQ(j["level"].get<int>(), 2);
  EXPECT_EQ(j["name"].get<std::string>(), "fault-manager");
  EXPECT_NE(j["message"].get<std::string>().find("EXCLUDE_SATELLITE G05"), std::string::npos)
      << j["message"];

  navbus::FilterCommandOutcome o;
  o.vehicle_id(1);
  o.command_id(4);
  o.issuer("operator");
  o.kind(navbus::CMD_COMPENSATE_BIAS);
  o.outcome(navbus::OUTCOME_REFUSED);
  o.reason(navbus::REJECT_OUT_OF_RANGE);
  o.detail("bias: 5 beyond 0.5");
  j = parsed(*derivedMessage(o, kReceivedUnixNs));
  EXPECT_EQ(j["level"].get<int>(), 4);  // ERROR
  EXPECT_EQ(j["name"].get<std::string>(), "filter/vehicle_1");
  EXPECT_NE(j["message"].get<std::string>().find("bias: 5 beyond 0.5"), std::string::npos);
  o.outcome(navbus::OUTCOME_CLAMPED);
  EXPECT_EQ(parsed(*derivedMessage(o, kReceivedUnixNs))["level"].get<int>(), 3);
}

TEST(FoxgloveChannels, EveryFieldOfAMessageIsInItsSchema) {
  const auto schemas = navbus::tool::derivedChannelSchemas(false);
  const json fix_schema = json::parse(schemas[0].schema);
  const json log_schema = json::parse(schemas[1].schema);
  EXPECT_EQ(schemas[0].schema_name, "foxglove.LocationFix");
  EXPECT_EQ(schemas[1].schema_name, "foxglove.Log");
  EXPECT_EQ(schemas[0].topic, "navbus/foxglove/location_fix");
  EXPECT_EQ(navbus::tool::derivedChannelSchemas(true)[1].topic, "/navbus/foxglove/log");
  navbus::FaultDecision d;
  d.detector("watchdog");
  const json fix = parsed(*derivedMessage(solutionAt(1.0, 2.0), kReceivedUnixNs));
  const json log = parsed(*derivedMessage(d, kReceivedUnixNs));
  for (const auto& [key, value] : fix.items()) {
    EXPECT_TRUE(fix_schema["properties"].contains(key)) << key;
  }
  for (const auto& [key, value] : log.items()) {
    EXPECT_TRUE(log_schema["properties"].contains(key)) << key;
  }
  EXPECT_EQ(fix_schema["properties"].size(), fix.size());
  EXPECT_EQ(log_schema["properties"].size(), log.size());
}
