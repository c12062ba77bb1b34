// The papers' scenario files: they load, the same seed gives the same data, and each injected
// fault appears at its scheduled time with its scheduled size (compared in lockstep with the
// fault-free run of the same seed, so the difference is the fault alone).
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/core/math/spectrum.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using navbus::sim::ScenarioConfig;
using navbus::sim::ScenarioSource;
using navbus::sim::SensorFrame;

namespace {
ScenarioConfig load(const std::string& name) {
  return navbus::sensor_sim::parseSimConfig(
             navbus::bus::loadYamlFile(std::string(navbus::test_paths::scenarioDir()) + "/" + name))
      .scenario;
}
double seconds(const ScenarioConfig& c, std::int64_t t_ns) {
  return 1e-9 * static_cast<double>(t_ns - c.start_time_ns);
}
}  // namespace

TEST(Scenarios, EveryScenarioFileLoads) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(navbus::test_paths::scenarioDir())) {
    if (e.path().extension() != ".yaml") continue;
    EXPECT_NO_THROW(
        navbus::sensor_sim::parseSimConfig(navbus::bus::loadYamlFile(e.path().string())))
        << e.path();
    ++n;
  }
  EXPECT_GE(n, 9);
}

TEST(Scenarios, SameSeedSameBitsOtherSeedOtherData) {
  auto c = load("seed004_land_vehicle.yaml");
  ScenarioSource a(c), b(c);
  c.seed = 2;
  ScenarioSource other(c);
  bool differs = false;
  for (int k = 0; k < 3000; ++k) {
    const SensorFrame fa = a.next(), fb = b.next(), fo = other.next();
    ASSERT_EQ(fa.increment.delta_vel_b_mps, fb.increment.delta_vel_b_mps);
    ASSERT_EQ(fa.increment.delta_angle_b_rad, fb.increment.delta_angle_b_rad);
    ASSERT_EQ(fa.has_gnss, fb.has_gnss);
    if (fa.has_gnss) {
      ASSERT_EQ(fa.fix.position.latitude_rad, fb.fix.position.latitude_rad);
    }
    differs = differs || fa.increment.delta_vel_b_mps != fo.increment.delta_vel_b_mps;
  }
  EXPECT_TRUE(differs);
}

TEST(Scenarios, Seed000AccelerometerStepAt502s) {
  const auto base = load("seed000_aircraft.yaml");
  const auto faulty = load("seed000_accel_step.yaml");
  ScenarioSource a(base), b(faulty);
  double max_before = 0, min_after = 1e9, max_after = 0;
  for (int k = 0; k < 50500; ++k) {  // to 505 s
    const SensorFrame fa = a.next(), fb = b.next();
    const double t = seconds(base, fa.time_ns);
    const Eigen::Vector3d d =
        (fb.increment.delta_vel_b_mps - fa.increment.delta_vel_b_mps) / fa.increment.interval_s;
    EXPECT_LT(std::abs(d.y()) + std::abs(d.z()), 1e-9);
    if (t <= 502.0) max_before = std::max(max_before, std::abs(d.x()));
    if (t > 502.0 + 1e-6) {
      min_after = std::min(min_after, d.x());
      max_after = std::max(max_after, d.x());
    }
  }
  std::printf(
      "seed 000 accel step: before 502 s %.2e m/s^2, after %.6f..%.6f m/s^2 (10 mg = %.6f)\n",
      max_before, min_after, max_after, 10e-3 * 9.80665);
  EXPECT_LT(max_before, 1e-9);
  EXPECT_NEAR(min_after, 10e-3 * 9.80665, 1e-9);
  EXPECT_NEAR(max_after, 10e-3 * 9.80665, 1e-9);
}

TEST(Scenarios, Seed000PseudorangeRampFrom650sSaturatingAt250m) {
  const auto base = load("seed000_aircraft.yaml");
  const auto faulty = load("seed000_pseudorange_ramp.yaml");
  ScenarioSource a(base), b(faulty);
  int checked = 0;
  for (int k = 0; k < 66500; ++k) {  // to 665 s
    const SensorFrame fa = a.next(), fb = b.next();
    if (!fa.has_gnss) continue;
    const double t = seconds(base, fa.time_ns);
    ASSERT_EQ(fa.gnss.satellites.size(), fb.gnss.satellites.size());
    for (std::size_t i = 0; i < fa.gnss.satellites.size(); ++i) {
      const double d = fb.gnss.satellites[i].pseudorange_m - fa.gnss.satellites[i].pseudorange_m;
      const double expected =
          fa.gnss.satellites[i].sv_id == 13 && t >= 650 ? std::min(25.0 * (t - 650), 250.0) : 0.0;
      EXPECT_NEAR(d, expected, 1e-6) << "t " << t << " sv " << fa.gnss.satellites[i].sv_id;
      checked += fa.gnss.satellites[i].sv_id == 13 ? 1 : 0;
    }
  }
  EXPECT_EQ(checked, 665);  // sv 13 tracked every epoch
}

TEST(Scenarios, Seed001GpsPositionPulseOf55mFor20s) {
  auto base = load("seed001_leo.yaml");
  auto faulty = load("seed001_gps_pulse.yaml");
  ScenarioSource a(base), b(faulty);
  int in_pulse = 0;
  for (int k = 0; k < 200 * 625; ++k) {  // to 625 s
    const SensorFrame fa = a.next(), fb = b.next();
    if (!fa.has_gnss) continue;
    const double t = seconds(base, fa.time_ns);
    const double r =
        navbus::core::earth::radiiOfCurvature(fa.fix.position.latitude_rad).meridian_m +
        fa.fix.position.height_m;
    const double dn = (fb.fix.position.latitude_rad - fa.fix.position.latitude_rad) * r;
    const bool active = t >= 600.0 && t < 620.0;
    EXPECT_NEAR(dn, active ? 55.0 : 0.0, 1e-3) << "t " << t;
    in_pulse += active ? 1 : 0;
  }
  EXPECT_EQ(in_pulse, 200);  // 20 s at 10 Hz
}

TEST(Scenarios, Seed003DitherInTheRawStreamAndStuckAccelerometers) {
  const auto c = load("seed003_laser_ins.yaml");
  ScenarioSource src(c);
  std::vector<double> ax_before, ax_after, gx, ay_after;
  double dv_max = 0;
  for (int k = 0; k < 100 * 62; ++k) {  // to 62 s
    const SensorFrame f = src.next();
    const double t = seconds(c, f.time_ns);
    for (const auto& s : f.raw.samples) {
      if (t > 38.0 && t <= 39.0) ax_before.push_back(s.specific_force_b_mps2.x());
      if (t > 38.0 && t <= 39.0) gx.push_back(s.angular_rate_b_radps.x());
      if (t > 45.0 && t <= 46.0) ax_after.push_back(s.specific_force_b_mps2.x());
      if (t > 61.0) ay_after.push_back(s.specific_force_b_mps2.y());
    }
    // The navigation-rate increments are dither-stripped: no 0.05 g oscillation in them.
    dv_max = std::max(dv_max, std::abs(f.increment.delta_vel_b_mps.x() / f.increment.interval_s));
  }
  const double rate = 2400.0;
  // Before its fault, accelerometer x shows all three dither frequencies.
  const auto peaks = navbus::core::largestPeaks(navbus::core::amplitudeSpectrum(ax_before, rate),
                                                rate, ax_before.size(), 300, 1200, 3);
  ASSERT_EQ(peaks.size(), 3u);
  for (double f : {373.0, 441.0, 409.0}) {
    EXPECT_TRUE(std::any_of(peaks.begin(), peaks.end(), [&](const auto& p) {
      return std::abs(p.frequency_hz - f) <= 1;
    })) << f;
  }
  // The gyro shows its dither and the differences to the other two.
  const auto gspec = navbus::core::amplitudeSpectrum(gx, rate);
  const auto gpeak = navbus::core::largestPeaks(gspec, rate, gx.size(), 300, 1200, 1);
  const auto glow = navbus::core::largestPeaks(gspec, rate, gx.size(), 10, 100, 2);
  ASSERT_EQ(gpeak.size(), 1u);
  ASSERT_EQ(glow.size(), 2u);
  EXPECT_NEAR(gpeak[0].frequency_hz, 373.0, 1.0);
  EXPECT_NEAR(std::min(glow[0].frequency_hz, glow[1].frequency_hz), 36.0, 1.0);
  EXPECT_NEAR(std::max(glow[0].frequency_hz, glow[1].frequency_hz), 68.0, 1.0);
  // After 40 s, x is stuck: a constant, no dither at all; y is stuck after 60 s.
  EXPECT_EQ(*std::min_element(ax_after.begin(), ax_after.end()),
            *std::max_element(ax_after.begin(), ax_after.end()));
  EXPECT_EQ(*std::min_element(ay_after.begin(), ay_after.end()),
            *std::max_element(ay_after.begin(), ay_after.end()));
  std::printf(
      "seed 003: accel x peaks %.0f %.0f %.0f Hz before 40 s, constant %.6f m/s^2 after; gyro x "
      "%.0f Hz, "
      "trapping %.0f and %.0f Hz\n",
      peaks[0].frequency_hz, peaks[1].frequency_hz, peaks[2].frequency_hz, ax_after.front(),
      gpeak[0].frequency_hz, glow[0].frequency_hz, glow[1].frequency_hz);
  EXPECT_LT(dv_max, 0.01);  // bias 50 ug + noise, far below the 0.05 g dither
}

TEST(Scenarios, Seed004GnssOutagesAt50To80And110To130s) {
  const auto c = load("seed004_land_vehicle.yaml");
  ScenarioSource src(c);
  int epochs = 0;
  for (int k = 0; k < 50 * 160; ++k) {
    const SensorFrame f = src.next();
    const double t = seconds(c, f.time_ns);
    const bool out = (t >= 50 && t < 80) || (t >= 110 && t < 130);
    if (f.has_gnss) {
      ++epochs;
      EXPECT_FALSE(out) << "GNSS epoch during an outage at " << t;
    } else if (std::abs(t - std::round(t)) < 1e-9) {
      EXPECT_TRUE(out) << "no GNSS epoch at " << t;
    }
  }
  EXPECT_EQ(epochs, 160 - 30 - 20);
}

TEST(Scenarios, StarTrackerOutageAndBiasFaults) {
  ScenarioConfig c;
  c.star_tracker.bias_rad = 0.0;
  ScenarioConfig f = c;
  navbus::sim::Fault out;
  out.kind = navbus::sim::FaultKind::kStarTrackerOutage;
  out.start_s = 1.0;
  out.end_s = 2.0;
  navbus::sim::Fault bias;
  bias.kind = navbus::sim::FaultKind::kStarTrackerBias;
  bias.start_s = 3.0;
  bias.vector = Eigen::Vector3d(0, 0, 1e-4);
  f.faults = navbus::sim::FaultSchedule({out, bias});
  ScenarioSource a(c), b(f);
  for (int k = 0; k < 400; ++k) {
    const SensorFrame fa = a.next(), fb = b.next();
    const double t = seconds(c, fa.time_ns);
    if (!fa.has_star_tracker) continue;
    EXPECT_EQ(fb.has_star_tracker, !(t >= 1.0 && t < 2.0)) << t;
    if (fb.has_star_tracker) {
      const double angle =
          Eigen::AngleAxisd(fa.star_tracker.q_b_to_i.conjugate() * fb.star_tracker.q_b_to_i)
              .angle();
      EXPECT_NEAR(angle, t >= 3.0 ? 1e-4 : 0.0, 1e-12) << t;
    }
  }
}

TEST(Scenarios, AnOutageAddressedToOneReceiverSilencesThatReceiverOnly) {
  // Given the dual-receiver aircraft with receiver 2 out from 20 s to 30 s, then receiver 2 has
  // no epoch in that time and receiver 1 (its epochs and fixes) every one, bit for bit those of
  // the run without the outage (the silent receiver is observed all the same: nothing else
  // moves); an outage naming no receiver still silences all. An unknown receiver is refused
  // naming the field.
  auto c = load("seed000_dual_receivers.yaml");
  const auto clean = c;
  navbus::sim::Fault out;
  out.kind = navbus::sim::FaultKind::kGnssOutage;
  out.start_s = 20.0;
  out.end_s = 30.0;
  out.receiver = 1;  // the first further receiver (id 2)
  std::vector<navbus::sim::Fault> faults = c.faults.faults();
  faults.push_back(out);
  c.faults = navbus::sim::FaultSchedule(faults);
  ScenarioSource a(clean), b(c);
  int silent = 0, epochs = 0;
  for (int k = 0; k < 100 * 40; ++k) {
    const SensorFrame fa = a.next(), fb = b.next();
    ASSERT_EQ(fa.has_gnss, fb.has_gnss);
    if (!fa.has_gnss) continue;
    ++epochs;
    const double t = seconds(c, fb.time_ns);
    ASSERT_TRUE(fb.has_extra_gnss);
    EXPECT_EQ(fb.extra_gnss_silent.at(0), t >= 20.0 && t < 30.0) << t;
    silent += fb.extra_gnss_silent.at(0) ? 1 : 0;
    ASSERT_EQ(fa.gnss.satellites.size(), fb.gnss.satellites.size());
    for (std::size_t i = 0; i < fa.gnss.satellites.size(); ++i)
      EXPECT_EQ(fa.gnss.satellites[i].pseudorange_m, fb.gnss.satellites[i].pseudorange_m);
    EXPECT_EQ(fa.extra_gnss.at(0).satellites.size(), fb.extra_gnss.at(0).satellites.size());
  }
  EXPECT_EQ(epochs, 40);
  EXPECT_EQ(silent, 10);
  EXPECT_FALSE(c.faults.receiverOut(25.0, 0));
  EXPECT_TRUE(c.faults.receiverOut(25.0, 1));
  EXPECT_FALSE(c.faults.gnssOut(25.0));
  out.receiver = -1;  // every receiver's
  EXPECT_TRUE(navbus::sim::FaultSchedule({out}).receiverOut(25.0, 0));
  EXPECT_TRUE(navbus::sim::FaultSchedule({out}).gnssOut(25.0));
  YAML::Node root = navbus::bus::loadYamlFile(std::string(navbus::test_paths::scenarioDir()) +
                                              "/seed000_dual_receivers.yaml");
  root["faults"] = YAML::Load("[{type: gnss_outage, start_s: 20, duration_s: 10, receiver_id: 9}]");
  try {
    navbus::sensor_sim::parseSimConfig(root);
    FAIL() << "an outage of an unknown receiver was accepted";
  } catch (const navbus::bus::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("faults[0].receiver_id = 9"), std::string::npos)
        << e.what();
  }
  root["faults"] = YAML::Load("[{type: gnss_outage, start_s: 20, duration_s: 10, receiver_id: 2}]");
  const auto parsed = navbus::sensor_sim::parseSimConfig(root).scenario;
  EXPECT_TRUE(parsed.faults.receiverOut(25.0, 1));
  EXPECT_FALSE(parsed.faults.receiverOut(25.0, 0));
}

TEST(Scenarios, MultipathOnOneReceiversSatelliteFollowsItsSineAndNothingElse) {
  // Given the dual-receiver aircraft with a 5 m multipath of period 60 s on satellite 13 of
  // receiver 2 from 100 s, then receiver 2's satellite 13 pseudorange error is 5 sin(2 pi (t -
  // 100) / 60) m while active (2.5 m at 105 s, 5 m at 115 s, 0 before 100 s), and receiver 1's
  // and receiver 2's other satellites get none.
  YAML::Node root = navbus::bus::loadYamlFile(std::string(navbus::test_paths::scenarioDir()) +
                                              "/seed000_dual_receivers.yaml");
  YAML::Node f;
  f["type"] = "gnss_multipath";
  f["start_s"] = 100.0;
  f["sv_id"] = 13;
  f["receiver_id"] = 2;
  f["amplitude_m"] = 5.0;
  f["period_s"] = 60.0;
  root["faults"] = YAML::Node(YAML::NodeType::Sequence);
  root["faults"].push_back(f);
  const navbus::sim::FaultSchedule faults =
      navbus::sensor_sim::parseSimConfig(root).scenario.faults;
  EXPECT_EQ(faults.pseudorangeError(13, 99.0, 1), 0.0);
  EXPECT_NEAR(faults.pseudorangeError(13, 105.0, 1), 2.5, 1e-12);
  EXPECT_NEAR(faults.pseudorangeError(13, 115.0, 1), 5.0, 1e-12);
  EXPECT_EQ(faults.pseudorangeError(13, 115.0, 0), 0.0);
  EXPECT_EQ(faults.pseudorangeError(12, 115.0, 1), 0.0);
  // A period that would divide by zero is refused naming the field.
  f["period_s"] = 0.0;
  root["faults"][0] = f;
  try {
    navbus::sensor_sim::parseSimConfig(root);
    FAIL() << "a zero period was taken";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("faults[0].period_s"), std::string::npos) << e.what();
  }
}
