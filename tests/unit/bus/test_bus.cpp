// Boundary validation, counters, configuration errors and the participant skeleton.
#include <cmath>
#include <limits>
#include <vector>

#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <gtest/gtest.h>
#include <navbus_idl/ImuPubSubTypes.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/bus/dds_context.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/bus/participant.hpp"
#include "navbus/bus/stop_after_end.hpp"
#include "navbus/bus/stream_end.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/bus/validation.hpp"
#include "navbus/bus/writer_gate.hpp"

using navbus::bus::SequenceTracker;
using navbus::bus::validate;
using navbus::bus::ValidationLimits;

namespace {
navbus::ImuIncrement goodImu() {
  navbus::ImuIncrement m;
  m.sensor_id(1);
  m.seq(1);
  m.time_gps_ns(1'000'000'000);
  m.interval_ns(10'000'000);
  m.delta_vel_b_mps({0.0, 0.0, -0.098});
  m.delta_angle_b_rad({5e-7, 0.0, -5e-7});
  return m;
}
navbus::GnssObservationEpoch goodEpoch() {
  navbus::GnssObservationEpoch e;
  navbus::GnssSatelliteMeasurement s;
  s.sv_id(5);
  s.pseudorange_m(2.2e7);
  s.pseudorange_rate_mps(300.0);
  s.sat_pos_ecef_m({1.5e7, 1.5e7, 1.2e7});
  s.cn0_dbhz(45.0);
  s.pseudorange_sigma_m(3.0);
  s.pseudorange_rate_sigma_mps(0.05);
  s.valid(true);
  e.satellites().push_back(s);
  return e;
}
}  // namespace

TEST(Validation, AcceptsAPhysicalImuIncrement) {
  EXPECT_FALSE(validate(goodImu(), ValidationLimits{}));
}

TEST(Validation, RejectsNonFiniteImuFieldsNamingTheField) {
  auto m = goodImu();
  m.delta_vel_b_mps()[2] = std::numeric_limits<double>::quiet_NaN();
  const auto r = validate(m, ValidationLimits{});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->reason, navbus::REJECT_NOT_FINITE);
  EXPECT_EQ(r->field, "delta_vel_b_mps[2]");
  m = goodImu();
  m.delta_angle_b_rad()[0] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(validate(m, ValidationLimits{})->field, "delta_angle_b_rad[0]");
}

TEST(Validation, RejectsOutOfRangeAndBadIntervals) {
  auto m = goodImu();
  m.delta_vel_b_mps()[0] = 100.0;  // 10000 m/s^2 over 10 ms
  EXPECT_EQ(validate(m, ValidationLimits{})->reason, navbus::REJECT_OUT_OF_RANGE);
  m = goodImu();
  m.delta_angle_b_rad()[1] = 1.0;  // 100 rad/s
  EXPECT_EQ(validate(m, ValidationLimits{})->reason, navbus::REJECT_OUT_OF_RANGE);
  m = goodImu();
  m.interval_ns(0);
  const auto r = validate(m, ValidationLimits{});
  EXPECT_EQ(r->reason, navbus::REJECT_BAD_INTERVAL);
  EXPECT_EQ(r->value, 0.0);
}

TEST(Validation, ARawBlockNamesTheSampleAndTheFieldRefused) {
  // Given a raw block of three good samples, then it passes; when the third one's x rate is NaN,
  // or the second one's specific force beyond the limit, the rejection names that sample.
  navbus::ImuRawBlock block;
  block.sensor_id(1);
  block.sample_period_ns(416'667);
  for (int i = 0; i < 3; ++i) {
    navbus::ImuRawSample x;
    x.specific_force_b_mps2({0.0, 0.0, -9.81});
    block.samples().push_back(x);
  }
  EXPECT_FALSE(validate(block, ValidationLimits{}));
  block.samples()[2].angular_rate_b_radps()[0] = std::nan("");
  auto r = validate(block, ValidationLimits{});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->reason, navbus::REJECT_NOT_FINITE);
  EXPECT_EQ(r->field, "samples[2].angular_rate_b_radps[0]");
  block.samples()[2].angular_rate_b_radps()[0] = 0.0;
  block.samples()[1].specific_force_b_mps2()[2] = -1e6;
  r = validate(block, ValidationLimits{});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->reason, navbus::REJECT_OUT_OF_RANGE);
  EXPECT_EQ(r->field, "samples[1].|specific_force_b_mps2|");
}

TEST(Validation, GnssSatellitesScreenedOneByOne) {
  using navbus::bus::screenSatellites;
  EXPECT_TRUE(screenSatellites(goodEpoch(), ValidationLimits{}).empty());
  auto e = goodEpoch();
  e.satellites()[0].sv_id(40);
  auto r = screenSatellites(e, ValidationLimits{});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].rejection.reason, navbus::REJECT_UNKNOWN_SATELLITE);
  EXPECT_EQ(r[0].rejection.field, "satellites[0].sv_id");
  EXPECT_EQ(r[0].rejection.value, 40.0);
  EXPECT_FALSE(validate(e, ValidationLimits{}));  // the epoch itself stands
  e = goodEpoch();
  e.satellites()[0].pseudorange_m(1.0e3);
  EXPECT_EQ(screenSatellites(e, ValidationLimits{})[0].rejection.reason,
            navbus::REJECT_OUT_OF_RANGE);
  e = goodEpoch();
  e.satellites()[0].sat_pos_ecef_m()[1] = std::nan("");
  EXPECT_EQ(screenSatellites(e, ValidationLimits{})[0].rejection.field,
            "satellites[0].sat_pos_ecef_m[1]");
  // Implausible sigmas, both ways.
  for (double sigma : {1e-300, 1e-3, 5e3}) {
    e = goodEpoch();
    e.satellites()[0].pseudorange_sigma_m(sigma);
    r = screenSatellites(e, ValidationLimits{});
    ASSERT_EQ(r.size(), 1u) << sigma;
    EXPECT_EQ(r[0].rejection.field, "satellites[0].pseudorange_sigma_m");
  }
  e = goodEpoch();
  e.satellites()[0].pseudorange_rate_sigma_mps(0.0);
  EXPECT_EQ(screenSatellites(e, ValidationLimits{})[0].rejection.field,
            "satellites[0].pseudorange_rate_sigma_mps");
  // The same id twice: both copies go, a third satellite stays.
  e = goodEpoch();
  e.satellites().push_back(e.satellites()[0]);
  e.satellites().push_back(e.satellites()[0]);
  e.satellites()[2].sv_id(7);
  r = screenSatellites(e, ValidationLimits{});
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].index, 0u);
  EXPECT_EQ(r[1].index, 1u);
  EXPECT_EQ(r[1].rejection.reason, navbus::REJECT_DUPLICATE_SATELLITE);
  const auto kept = navbus::bus::toCore(e, r);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].sv_id, 7);
}

TEST(SequenceTracker, ForwardJumpRejectedUnlessTheSamplesAfterItConfirmIt) {
  using navbus::bus::SequenceTracker;
  navbus::bus::TimeReference reference;
  SequenceTracker imu({2'000'000'000, 3}, &reference), gnss({2'000'000'000, 3}, &reference);
  const std::uint64_t t0 = 1'000'000'000'000, dt = 10'000'000, hour = 3'600'000'000'000;
  std::uint64_t seq = 0, t = t0;
  auto next = [&] { return imu.check(1, ++seq, t += dt); };
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(next().rejection);
  // One sample stamped an hour ahead: rejected and not adopted; the stream goes on.
  auto o = imu.check(1, seq + 1, t + hour);
  ASSERT_TRUE(o.rejection);
  EXPECT_EQ(o.rejection->reason, navbus::REJECT_TIME_JUMP);
  for (int k = 0; k < 5; ++k) EXPECT_FALSE(next().rejection) << k;
  EXPECT_EQ(reference.latest_ns, t);
  // Another stream is judged against the participant's reference too.
  EXPECT_EQ(gnss.check(1, 1, t + hour).rejection->reason, navbus::REJECT_TIME_JUMP);
  EXPECT_FALSE(gnss.check(1, 2, t).rejection);
  // A real resumption after 60 s of silence: the first two samples are refused as candidates
  // of a chain, the third, continuing from them, is accepted and adopted, and says that the
  // two before it belong to the chain (a caller that held them uses them).
  t += 60'000'000'000;
  o = next();
  EXPECT_EQ(o.rejection->reason, navbus::REJECT_TIME_JUMP);
  EXPECT_EQ(o.jump_candidate, 1);
  o = next();
  EXPECT_EQ(o.rejection->reason, navbus::REJECT_TIME_JUMP);
  EXPECT_EQ(o.jump_candidate, 2);
  o = next();
  EXPECT_FALSE(o.rejection);
  EXPECT_TRUE(o.jump_adopted);
  EXPECT_EQ(o.jump_held, 2);
  EXPECT_EQ(o.missing, 0u);
  o = next();
  EXPECT_FALSE(o.rejection);
  EXPECT_EQ(o.jump_held, 0);
  // A stream that starts more than the tolerance ahead of the others: its first sample number
  // is the chain's, so nothing counts as missed before it.
  SequenceTracker star({2'000'000'000, 3}, &reference);
  const std::uint64_t ahead = reference.latest_ns + 5'000'000'000;
  EXPECT_EQ(star.check(1, 1, ahead).jump_candidate, 1);
  EXPECT_EQ(star.check(1, 2, ahead + dt).jump_candidate, 2);
  o = star.check(1, 3, ahead + 2 * dt);
  EXPECT_TRUE(o.jump_adopted);
  EXPECT_EQ(o.jump_held, 2);
  EXPECT_EQ(o.missing_before_first, 0u);
  // Without a rule nothing is judged (the fault manager's counters).
  SequenceTracker plain;
  EXPECT_FALSE(plain.check(1, 1, t0).rejection);
  EXPECT_FALSE(plain.check(1, 2, t0 + hour).rejection);
}

TEST(Validation, StarTrackerQuaternionMustBeUnit) {
  navbus::StarTrackerAttitude s;
  s.q_b_to_i({1.0, 0.0, 0.0, 0.0});
  s.sigma_b_rad({1e-6, 1e-6, 1e-5});
  s.valid(true);
  EXPECT_FALSE(validate(s, ValidationLimits{}));
  s.q_b_to_i({1.0, 0.01, 0.0, 0.0});
  EXPECT_EQ(validate(s, ValidationLimits{})->reason, navbus::REJECT_BAD_QUATERNION);
  s.valid(false);  // an invalid sample's quaternion is not used, so not judged
  EXPECT_FALSE(validate(s, ValidationLimits{}));
}

TEST(Validation, DiagnosticsProcessNoiseScaleIsFiniteAndNotNegative) {
  // One pseudorange row of an epoch, as the filter publishes it: the scale on Q defaults to 1.
  navbus::core::EpochDiagnostics d;
  d.sv_ids = {5};
  d.is_rate = {false};
  d.used = {true};
  d.test_ratio = {0.1};
  d.innovation = Eigen::VectorXd::Constant(1, 0.5);
  d.innovation_cov = Eigen::MatrixXd::Constant(1, 1, 4.0);
  d.h = Eigen::MatrixXd::Zero(1, navbus::core::layout::kSize);
  d.k = Eigen::MatrixXd::Zero(navbus::core::layout::kSize, 1);
  navbus::FilterDiagnostics m = navbus::bus::toIdl(d, 1, 1, 1'400'000'000'000'000'000);
  EXPECT_DOUBLE_EQ(m.process_noise_scale(), 1.0);
  EXPECT_FALSE(validate(m, ValidationLimits{}));
  m.process_noise_scale(0.0);  // a producer that does not report it
  EXPECT_FALSE(validate(m, ValidationLimits{}));
  m.process_noise_scale(std::numeric_limits<double>::quiet_NaN());
  ASSERT_TRUE(validate(m, ValidationLimits{}));
  EXPECT_EQ(validate(m, ValidationLimits{})->reason, navbus::REJECT_NOT_FINITE);
  EXPECT_EQ(validate(m, ValidationLimits{})->field, "process_noise_scale");
  m.process_noise_scale(-2.0);
  EXPECT_EQ(validate(m, ValidationLimits{})->reason, navbus::REJECT_OUT_OF_RANGE);
  EXPECT_EQ(validate(m, ValidationLimits{})->field, "process_noise_scale");
}

TEST(Validation, GnssFixRanges) {
  navbus::GnssFix f;
  f.valid(false);
  EXPECT_FALSE(validate(f, ValidationLimits{}));  // invalid fixes: finiteness only
  f.valid(true);
  f.latitude_rad(0.5);
  f.longitude_rad(2.0);
  f.height_m(100.0);
  f.pos_sigma_ned_m({1, 1, 2});
  f.vel_sigma_ned_mps({0.1, 0.1, 0.2});
  EXPECT_FALSE(validate(f, ValidationLimits{}));
  f.latitude_rad(2.0);
  EXPECT_EQ(validate(f, ValidationLimits{})->field, "latitude_rad");
  f.latitude_rad(0.5);
  f.pos_sigma_ned_m()[1] = 0.0;
  EXPECT_EQ(validate(f, ValidationLimits{})->field, "pos_sigma_ned_m[1]");
}

TEST(SequenceTracker, DuplicatesOrderAndGaps) {
  SequenceTracker t;
  EXPECT_FALSE(t.check(1, 1, 100).rejection);
  auto o = t.check(1, 1, 100);
  ASSERT_TRUE(o.rejection);
  EXPECT_EQ(o.rejection->reason, navbus::REJECT_DUPLICATE);
  o = t.check(1, 2, 90);
  EXPECT_EQ(o.rejection->reason, navbus::REJECT_TIME_NOT_MONOTONIC);
  o = t.check(1, 5, 130);
  EXPECT_FALSE(o.rejection);
  EXPECT_EQ(o.missing, 3u);
  o = t.check(1, 1, 200);  // writer restarted: sequence back, time forward
  EXPECT_FALSE(o.rejection);
  EXPECT_TRUE(o.restarted);
  EXPECT_FALSE(t.check(2, 1, 50).rejection);  // sensors are independent
}

TEST(SequenceTracker, SamplesNumberedBeforeTheFirstOneTakenAreCounted) {
  // Counters start at 1: a first sample numbered 187 means 186 were never received (the soak
  // found a best-effort reader that missed the start of a stream, uncounted).
  SequenceTracker t;
  auto o = t.check(1, 187, 100);
  EXPECT_EQ(o.missing, 186u);
  EXPECT_EQ(o.missing_before_first, 186u);
  EXPECT_EQ(t.check(2, 1, 100).missing, 0u);  // a stream taken from its first sample
  // After a stream was set aside (declared lost), its start is not counted again.
  t.reset(1);
  o = t.check(1, 500, 200);
  EXPECT_EQ(o.missing, 0u);
  EXPECT_EQ(o.missing_before_first, 0u);
  // A new run (the source restarted) counts from its start again.
  t.resetAll();
  EXPECT_EQ(t.check(1, 3, 300).missing_before_first, 2u);
}

TEST(SequenceTracker, SourceRestartAtAnEarlierTimeIsConfirmedByTheSamplesAfterIt) {
  SequenceTracker t(navbus::bus::TimeJumpRule{50, 3}, nullptr);
  for (std::uint64_t k = 1; k <= 10; ++k)
    EXPECT_FALSE(t.check(1, 100 + k, 1000 + 10 * k).rejection);
  // One stale sample (time and sequence behind) followed by the stream going on: rejected, and
  // the candidate forgotten.
  EXPECT_EQ(t.check(1, 50, 500).rejection->reason, navbus::REJECT_TIME_NOT_MONOTONIC);
  EXPECT_FALSE(t.check(1, 111, 1110).rejection);
  EXPECT_EQ(t.check(1, 51, 510).rejection->reason, navbus::REJECT_TIME_NOT_MONOTONIC);
  // A restart: sequence and time back, and the samples after it continue from it.
  EXPECT_EQ(t.check(1, 1, 200).rejection->reason, navbus::REJECT_TIME_NOT_MONOTONIC);
  EXPECT_EQ(t.check(1, 2, 210).rejection->reason, navbus::REJECT_TIME_NOT_MONOTONIC);
  const auto o = t.check(1, 3, 220);
  EXPECT_FALSE(o.rejection);
  EXPECT_TRUE(o.source_restarted);
  EXPECT_FALSE(t.check(1, 4, 230).rejection);  // the stream goes on from the new run
  EXPECT_EQ(t.check(1, 5, 1120).rejection->reason, navbus::REJECT_TIME_JUMP);
  // Time back with the sequence going on is no restart, however many samples.
  for (std::uint64_t k = 0; k < 5; ++k)
    EXPECT_EQ(t.check(2, 10 + k, 1000 - k).rejection.has_value(), k > 0);
}

TEST(HealthCounters, ReportCarriesEveryStreamAndReason) {
  navbus::bus::HealthCounters h("p");
  auto& s = h.stream("a");
  s.received = 10;
  s.accepted = 7;
  navbus::bus::StreamGate gate("a", s);
  gate.reject({navbus::REJECT_DUPLICATE, "seq", 3}, 1);
  gate.reject({navbus::REJECT_DUPLICATE, "seq", 4}, 1);
  gate.reject({navbus::REJECT_NOT_FINITE, "x", std::nan("")}, 1);
  h.stream("b");
  const navbus::Health r = h.report(navbus::STATE_RUNNING, 5);
  ASSERT_EQ(r.inputs().size(), 2u);
  EXPECT_EQ(r.inputs()[0].topic().to_string(), "a");
  ASSERT_EQ(r.inputs()[0].rejected().size(), 2u);
  std::uint64_t dup = 0;
  for (const auto& rc : r.inputs()[0].rejected()) {
    if (rc.reason() == navbus::REJECT_DUPLICATE) dup = rc.count();
  }
  EXPECT_EQ(dup, 2u);
  EXPECT_EQ(r.seq(), 1u);
}

TEST(HealthCounters, EachSensorOfATopicIsCountedUnderItsId) {
  // Three IMU units on one topic: unit 2 skips a sample, unit 3 sends a bad one; then ten ids
  // nobody configured. The first 8 ids are counted one by one, the rest together.
  navbus::bus::HealthCounters h("p");
  navbus::bus::StreamGate gate("imu", h.stream("imu"));
  for (std::uint32_t unit = 1; unit <= 3; ++unit) {
    for (std::uint64_t seq = 1; seq <= 5; ++seq) {
      if (unit == 2 && seq == 3) continue;  // lost on the way
      navbus::ImuIncrement m = goodImu();
      m.sensor_id(unit);
      if (unit == 3 && seq == 4) m.delta_vel_b_mps()[0] = std::nan("");
      gate.admit(m, unit, seq, 1000 * seq);
    }
  }
  for (std::uint32_t bogus = 100; bogus < 110; ++bogus) {
    gate.admit(goodImu(), bogus, 1, 1000);
    gate.unaccept(bogus);  // as the filter does for an id its configuration does not name
    gate.reject({navbus::REJECT_UNEXPECTED_SOURCE, "sensor_id", static_cast<double>(bogus)}, bogus);
  }
  const navbus::Health r = h.report(navbus::STATE_RUNNING, 5);
  ASSERT_EQ(r.inputs().size(), 1u);
  const navbus::StreamHealth& in = r.inputs()[0];
  EXPECT_EQ(in.accepted(), 13u);
  ASSERT_EQ(in.sensors().size(), navbus::bus::StreamCounters::kMaxSensors);
  EXPECT_EQ(in.sensors()[0].sensor_id(), 1u);
  EXPECT_EQ(in.sensors()[0].accepted(), 5u);
  EXPECT_EQ(in.sensors()[0].sequence_gaps(), 0u);
  EXPECT_EQ(in.sensors()[1].accepted(), 4u);
  EXPECT_EQ(in.sensors()[1].sequence_gaps(), 1u);
  EXPECT_EQ(in.sensors()[2].accepted(), 4u);
  EXPECT_EQ(in.sensors()[2].rejected(), 1u);
  for (std::size_t i = 3; i < in.sensors().size(); ++i) {
    EXPECT_EQ(in.sensors()[i].sensor_id(), 100u + (i - 3));
    EXPECT_EQ(in.sensors()[i].accepted(), 0u);
    EXPECT_EQ(in.sensors()[i].rejected(), 1u);
  }
  EXPECT_EQ(in.unlisted_sensor_samples(), 5u);  // ids 105 to 109, one sample each
  const std::string summary = h.summary();
  EXPECT_NE(summary.find("    sensor 2: accepted 4, rejected 0, sequence gaps 1"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("further sensor ids (not counted one by one): 5 samples"),
            std::string::npos)
      << summary;
}

TEST(Config, ErrorsNameTheKeyAndValue) {
  const YAML::Node n = YAML::Load("timing: {imu_rate_hz: fast}");
  try {
    navbus::bus::get<double>(n["timing"], "timing", "imu_rate_hz", 1.0);
    FAIL() << "no exception";
  } catch (const navbus::bus::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("timing.imu_rate_hz"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("fast"), std::string::npos);
  }
  EXPECT_THROW(navbus::bus::checkRange(500.0, 0, 232, "domain_id"), navbus::bus::ConfigError);
  EXPECT_THROW(navbus::bus::loadYamlFile("/nonexistent/x.yaml"), navbus::bus::ConfigError);
}

TEST(Skeleton, UnknownParticipantProfileIsAClearError) {
  navbus::bus::ParticipantOptions o;
  o.domain_id = 200;
  o.participant_profile = "no_such_profile";
  o.name = "unit";
  try {
    navbus::bus::DdsContext ctx(o);
    FAIL() << "no exception";
  } catch (const navbus::bus::DdsError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_profile"), std::string::npos);
  }
}

TEST(Skeleton, UnknownWriterProfileIsAClearErrorAndKnownOnesWork) {
  navbus::bus::ShutdownSignal shutdown;
  navbus::bus::Participant::Options o;
  o.dds.domain_id = 201;
  o.dds.participant_profile = navbus::bus::profile::kParticipantLoopback;
  o.dds.name = "unit";
  navbus::bus::Participant p(o, shutdown);
  try {
    p.createWriter<navbus::HealthPubSubType>("navbus/unit", "no_such_writer_profile");
    FAIL() << "no exception";
  } catch (const navbus::bus::DdsError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_writer_profile"), std::string::npos);
  }
  // A writer and a reader in one participant exchange a sample through the waitset loop.
  auto writer =
      p.createWriter<navbus::HealthPubSubType>("navbus/unit", navbus::bus::profile::kHealthWriter);
  int received = 0;
  p.subscribe<navbus::HealthPubSubType>("navbus/unit", navbus::bus::profile::kHealthReader,
                                        [&](const navbus::Health& h, const auto&) {
                                          received += h.participant().to_string() == "x" ? 1 : 0;
                                        });
  navbus::Health h;
  h.participant("x");
  ASSERT_TRUE(writer.write(h));
  for (int i = 0; i < 100 && received == 0; ++i) p.spinOnce(std::chrono::milliseconds(20));
  EXPECT_EQ(received, 1);
  EXPECT_EQ(p.health().find("navbus/unit")->received, 1u);
  // Shutdown requested from inside ends run().
  p.stop();
  p.run();
  EXPECT_EQ(p.state(), navbus::STATE_STOPPING);
}

// STARTING until the first input, then RUNNING, announced at once with the resume time (the
// first input to the report); a participant without inputs is RUNNING on its first iteration.
TEST(Skeleton, RunningWithTheFirstInputAnnouncedAtOnceWithTheResumeTime) {
  navbus::bus::ShutdownSignal shutdown;
  navbus::bus::Participant::Options o;
  o.dds.domain_id = 202;
  o.dds.participant_profile = navbus::bus::profile::kParticipantLoopback;
  o.dds.name = "unit-resume";
  o.health_period = std::chrono::hours(1);  // only the reports the state changes cause
  navbus::bus::Participant p(o, shutdown);
  std::vector<navbus::Health> reports;
  p.subscribe<navbus::HealthPubSubType>(navbus::bus::topic::kHealth,
                                        navbus::bus::profile::kHealthReader,
                                        [&](const navbus::Health& h, const auto&) {
                                          if (h.participant().to_string() == "unit-resume")
                                            reports.push_back(h);
                                        });
  // Durable history handed over on joining is no input either (an earlier run's decisions).
  auto durable = p.createWriter<navbus::HealthPubSubType>("navbus/unit-durable",
                                                          navbus::bus::profile::kHealthWriter);
  ASSERT_TRUE(durable.write(navbus::Health()));
  int durable_received = 0;
  p.subscribe<navbus::HealthPubSubType>("navbus/unit-durable", navbus::bus::profile::kHealthReader,
                                        [&](const auto&, const auto&) { ++durable_received; });
  auto writer = p.createWriter<navbus::ImuIncrementPubSubType>("navbus/unit",
                                                               navbus::bus::profile::kSensorWriter);
  int received = 0;
  p.subscribe<navbus::ImuIncrementPubSubType>("navbus/unit", navbus::bus::profile::kSensorReader,
                                              [&](const auto&, const auto&) { ++received; });
  for (int i = 0; i < 5; ++i) p.spinOnce(std::chrono::milliseconds(20));
  EXPECT_EQ(durable_received, 1);
  EXPECT_EQ(p.state(), navbus::STATE_STARTING);  // neither health nor durable history is input
  EXPECT_TRUE(reports.empty());
  for (int i = 0; i < 100 && writer.matchedReaders() == 0; ++i)
    p.spinOnce(std::chrono::milliseconds(10));
  ASSERT_TRUE(writer.write(navbus::ImuIncrement()));
  for (int i = 0; i < 100 && reports.empty(); ++i) p.spinOnce(std::chrono::milliseconds(20));
  EXPECT_EQ(received, 1);
  EXPECT_EQ(p.state(), navbus::STATE_RUNNING);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].state(), navbus::STATE_RUNNING);
  EXPECT_GT(reports[0].resume_ns(), 0u);
  EXPECT_LT(reports[0].resume_ns(), 1'000'000'000u);

  o.dds.name = "unit-source";
  navbus::bus::Participant source(o, shutdown);
  source.spinOnce(std::chrono::milliseconds(1));
  EXPECT_EQ(source.state(), navbus::STATE_RUNNING);
}

// A reliable KEEP_ALL reader (the filter's input profile) learns the announced end of a
// stream: the writer's dispose reaches it after the data, and the writer's wait for
// acknowledgments returns at once. Over the wire, not Fast DDS's intraprocess shortcut (which
// hid that Fast DDS 2.9.1 reliable readers with a DYNAMIC_REUSABLE history drop a dispose).
TEST(Skeleton, AReliableReaderLearnsTheAnnouncedEndOfAStream) {
  using eprosima::fastrtps::xmlparser::XMLProfileManager;
  const eprosima::fastrtps::LibrarySettingsAttributes before =
      XMLProfileManager::library_settings();
  eprosima::fastrtps::LibrarySettingsAttributes wire = before;
  wire.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  XMLProfileManager::library_settings(wire);
  struct Restore {
    eprosima::fastrtps::LibrarySettingsAttributes settings;
    ~Restore() { XMLProfileManager::library_settings(settings); }
  } restore{before};
  navbus::bus::ShutdownSignal shutdown;
  navbus::bus::Participant::Options o;
  o.dds.domain_id = 203;
  o.dds.participant_profile = navbus::bus::profile::kParticipantLoopback;
  o.dds.name = "unit-end";
  o.health_period = std::chrono::hours(1);
  navbus::bus::Participant reader_side(o, shutdown);
  o.dds.name = "unit-end-source";
  navbus::bus::Participant writer_side(o, shutdown);
  int samples = 0;
  int ends = 0;
  navbus::bus::ReaderCallbacks callbacks;
  callbacks.on_disposed = [&](const auto&) { ++ends; };
  reader_side.subscribe<navbus::ImuIncrementPubSubType>(
      navbus::bus::topic::kImuIncrement, navbus::bus::profile::kSensorReader,
      [&](const auto&, const auto&) { ++samples; }, callbacks);
  auto writer = writer_side.createWriter<navbus::ImuIncrementPubSubType>(
      navbus::bus::topic::kImuIncrement, navbus::bus::profile::kSensorWriter);
  for (int i = 0; i < 200 && writer.matchedReaders() == 0; ++i)
    reader_side.spinOnce(std::chrono::milliseconds(10));
  navbus::ImuIncrement m;
  m.sensor_id(7);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(writer.write(m));
  ASSERT_TRUE(writer.dispose(m));
  for (int i = 0; i < 200 && ends == 0; ++i) reader_side.spinOnce(std::chrono::milliseconds(10));
  EXPECT_EQ(samples, 10);
  EXPECT_EQ(ends, 1);
  // Every sample before the end was received: nothing counted as missed before it.
  EXPECT_EQ(reader_side.health().stream(navbus::bus::topic::kImuIncrement).sequence_gaps, 0u);
  EXPECT_EQ(writer.raw()->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(1, 0)),
            ReturnCode_t::RETCODE_OK);
}

// One writer per sensor id: the owner keeps it while alive, another writer is a second writer
// (reported once, counted every time), a new writer takes over after the owner's silence.
TEST(WriterPins, OwnerSecondWriterAndTakeover) {
  using V = navbus::bus::WriterPins::Verdict;
  navbus::bus::WriterPins pins(1'000'000'000);
  const navbus::bus::WriterId a{1}, b{2}, c{3};
  EXPECT_EQ(pins.check(7, a, 0), V::kOwner);
  EXPECT_EQ(pins.check(7, a, 100'000'000), V::kOwner);
  EXPECT_EQ(pins.check(7, b, 200'000'000), V::kNewSecondWriter);
  EXPECT_EQ(pins.check(7, b, 300'000'000), V::kSecondWriter);
  EXPECT_EQ(pins.check(8, b, 300'000'000), V::kOwner);              // another sensor id: b owns it
  EXPECT_EQ(pins.check(7, a, 900'000'000), V::kOwner);              // the owner goes on
  EXPECT_EQ(pins.check(7, c, 1'800'000'000), V::kNewSecondWriter);  // a silent 0.9 s: alive
  EXPECT_EQ(pins.check(7, c, 1'900'000'000), V::kTakeover);         // silent 1.0 s: gone
  EXPECT_EQ(pins.check(7, a, 2'000'000'000), V::kNewSecondWriter);  // the old owner is back
  EXPECT_EQ(navbus::bus::toString(a).substr(0, 4), "0100");
}

// The samples missed before a writer's announced end, from its RTPS sequence numbers (every
// change it wrote, data and dispose alike, numbered from 1).
TEST(StreamEndCounter, CountsTheChangesMissedBeforeTheDispose) {
  navbus::bus::StreamEndCounter ends;
  const navbus::bus::WriterId a{1}, b{2};
  EXPECT_EQ(ends.disposed(a, 5), 0u);  // nothing taken from a: nothing to count from
  for (std::int64_t seq : {1, 2, 3, 7, 8}) ends.taken(b, seq);  // 4-6: gaps a later sample shows
  EXPECT_EQ(ends.disposed(b, 9), 0u);                           // 8 was the last data
  ends.taken(a, 10);
  EXPECT_EQ(ends.disposed(a, 14), 3u);  // 11-13 never arrived
  EXPECT_EQ(ends.disposed(a, 15), 0u);  // a second instance's dispose right after
}

// --exit-when-ended (bus/stop_after_end.hpp): the announced end stops the participant after the
// grace, whatever the writers' liveliness does then; writers gone stop it only if none is alive
// again before the grace ends.
namespace {
/// Spins `p` for `d`; true if it was asked to stop meanwhile.
bool stoppedWithin(navbus::bus::Participant& p, std::chrono::milliseconds d) {
  const auto end = std::chrono::steady_clock::now() + d;
  while (!p.stopping() && std::chrono::steady_clock::now() < end)
    p.spinOnce(std::chrono::milliseconds(20));
  return p.stopping();
}
navbus::bus::Participant::Options stopTestOptions() {
  navbus::bus::Participant::Options o;
  o.dds.domain_id = 204;
  o.dds.participant_profile = navbus::bus::profile::kParticipantLoopback;
  o.dds.name = "unit-stop-after-end";
  return o;
}
constexpr std::chrono::milliseconds kGrace{500};
}  // namespace

TEST(StopAfterEnd, WritersGoneStopAfterTheGraceUnlessOneIsBack) {
  navbus::bus::ShutdownSignal shutdown;
  navbus::bus::Participant p(stopTestOptions(), shutdown);
  navbus::bus::StopAfterEnd stop(p, kGrace);
  stop.writersAlive(true);  // the writer matched: nothing to do
  EXPECT_FALSE(stoppedWithin(p, 2 * kGrace));
  stop.writersAlive(false);
  stop.writersAlive(true);  // back within the grace (a stale view after a stall)
  EXPECT_FALSE(stoppedWithin(p, 3 * kGrace));
  stop.writersAlive(false);
  EXPECT_TRUE(stoppedWithin(p, 6 * kGrace));
}

TEST(StopAfterEnd, TheAnnouncedEndIsNotCancelled) {
  navbus::bus::ShutdownSignal shutdown;
  navbus::bus::Participant p(stopTestOptions(), shutdown);
  navbus::bus::StopAfterEnd stop(p, kGrace);
  stop.ended();
  stop.writersAlive(false);  // the writer left after its dispose, as it does
  stop.writersAlive(true);   // and a new one came: the data this participant was for has ended
  EXPECT_TRUE(stoppedWithin(p, 6 * kGrace));
}
