// The dither monitor (seed 003) on synthetic raw streams: the simulator's dither model plus
// white noise, with stuck axes, missing lines, vehicle vibration and gaps.
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>

#include <gtest/gtest.h>

#include "navbus/core/integrity/dither_monitor.hpp"
#include "navbus/sim/dither.hpp"

namespace {
using navbus::core::DitherMonitor;
using navbus::core::DitherMonitorConfig;
using navbus::core::DitherWindow;
using navbus::core::kFirstGyroChannel;

constexpr double kRate = 2400.0;
constexpr std::int64_t kPeriodNs = 416667;

/// A synthetic raw stream: gravity on z, the seed-003 dither, white noise, optional stuck
/// channels, optional vibration in the vehicle-motion band.
struct Stream {
  navbus::sim::DitherModel dither{navbus::sim::DitherSpec{}};
  std::mt19937_64 rng{7};
  std::normal_distribution<double> unit{0.0, 1.0};
  double accel_noise_mps2{3.4e-3};  // 10 ug/sqrt(Hz) at 2400 Hz
  double gyro_noise_radps{1e-5};
  std::array<std::optional<double>, 6> stuck_since_s{};
  std::array<bool, 3> accel_line_present{true, true, true};
  double vibration_mps2{0.0};  ///< amplitude of 12 Hz and 37 Hz vehicle vibration

  void sample(double t, Eigen::Vector3d& f, Eigen::Vector3d& w) {
    const auto d = dither.at(t);
    for (int a = 0; a < 3; ++a) {
      f[a] = (a == 2 ? -9.8 : 0.0) + accel_noise_mps2 * unit(rng) +
             vibration_mps2 * (std::sin(2 * M_PI * 12.0 * t + a) + std::sin(2 * M_PI * 37.0 * t));
      // Lines the accelerometer picks up, one per gyro (seed 003 eq. 1).
      const auto& spec = dither.spec();
      for (int j = 0; j < 3; ++j) {
        if (!accel_line_present[static_cast<std::size_t>(j)]) continue;
        f[a] += (a == j ? spec.accel_own_axis_mps2 : spec.accel_cross_axis_mps2) *
                std::sin(2 * M_PI * spec.frequency_hz[j] * t);
      }
      w[a] = d.angular_rate_b_radps[a] + gyro_noise_radps * unit(rng) +
             0.2 * vibration_mps2 * std::sin(2 * M_PI * 41.0 * t);
    }
    for (int c = 0; c < 6; ++c) {
      const auto since = stuck_since_s[static_cast<std::size_t>(c)];
      if (since && t >= *since) (c < 3 ? f[c] : w[c - 3]) = c < 3 ? 0.123 : 1e-4;
    }
  }
};

struct Detection {
  int channel;
  double time_s;
  double onset_s;
};

/// Runs the monitor over `seconds` of the stream, skipping samples in [skip_from, skip_to).
std::vector<Detection> run(DitherMonitor& m, Stream& s, double seconds, double skip_from = -1,
                           double skip_to = -1) {
  std::vector<Detection> out;
  Eigen::Vector3d f, w;
  const auto n = static_cast<std::int64_t>(seconds * kRate);
  for (std::int64_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / kRate;
    s.sample(t, f, w);
    if (t >= skip_from && t < skip_to) continue;
    const DitherWindow* win = m.addSample(k * kPeriodNs, f, w);
    if (!win) continue;
    for (int c = 0; c < navbus::core::kDitherChannels; ++c) {
      if (win->changed[static_cast<std::size_t>(c)] && m.failed(c)) {
        out.push_back({c, static_cast<double>(win->end_time_ns) * 1e-9,
                       static_cast<double>(m.lastPassedStartNs(c)) * 1e-9});
      }
    }
  }
  return out;
}
}  // namespace

TEST(DitherMonitor, HealthyStreamGivesNoAlarmOnAnyAxis) {
  DitherMonitor m(DitherMonitorConfig{});
  Stream s;
  const auto d = run(m, s, 120.0);
  EXPECT_TRUE(d.empty()) << "first alarm on channel " << d.front().channel << " at "
                         << d.front().time_s;
  EXPECT_GT(m.counters().windows, 2000u);
  EXPECT_EQ(m.counters().gyro_windows_skipped, 0u);  // still: the gyros were checked too
}

TEST(DitherMonitor, StuckAccelerometerIsFlaggedOnItsAxisWithinHalfASecond) {
  for (int axis = 0; axis < 3; ++axis) {
    DitherMonitor m(DitherMonitorConfig{});
    Stream s;
    const double fault_s = 5.0 + 0.37 * axis;  // not aligned with the window grid
    s.stuck_since_s[static_cast<std::size_t>(axis)] = fault_s;
    const auto d = run(m, s, 10.0);
    ASSERT_EQ(d.size(), 1u) << "axis " << axis;
    EXPECT_EQ(d[0].channel, axis);
    EXPECT_GT(d[0].time_s, fault_s);
    EXPECT_LE(d[0].time_s, fault_s + 0.5);
    EXPECT_LE(d[0].onset_s, fault_s);  // the fault began after the onset reported
    EXPECT_GT(d[0].onset_s, fault_s - 0.5);
    std::printf("accel %c stuck at %.2f s: flagged at %.3f s (%.0f ms), onset after %.3f s\n",
                "xyz"[axis], fault_s, d[0].time_s, 1e3 * (d[0].time_s - fault_s), d[0].onset_s);
  }
}

TEST(DitherMonitor, AnyOfTheThreeLinesCountsAsHealthy) {
  DitherMonitor m(DitherMonitorConfig{});
  Stream s;
  s.accel_line_present = {false, true, false};  // only the y gyro's line is left
  EXPECT_TRUE(run(m, s, 20.0).empty());
}

TEST(DitherMonitor, AllLinesMissingIsAFaultOnEveryAccelerometer) {
  DitherMonitor m(DitherMonitorConfig{});
  Stream s;
  s.accel_line_present = {false, false, false};  // noise only: the largest peak is anywhere
  const auto d = run(m, s, 2.0);
  ASSERT_EQ(d.size(), 3u);
  for (const auto& x : d) EXPECT_LT(x.channel, kFirstGyroChannel);
}

TEST(DitherMonitor, GapsDropTheirWindowAndNeverAlarm) {
  DitherMonitor m(DitherMonitorConfig{});
  Stream s;
  // Lose 1 ms, 10 ms and 100 ms of samples (one sample, a block, ten blocks).
  auto d = run(m, s, 3.0, 1.0, 1.001);
  EXPECT_TRUE(d.empty());
  DitherMonitor m2(DitherMonitorConfig{});
  Stream s2;
  d = run(m2, s2, 3.0, 1.5, 1.6);
  EXPECT_TRUE(d.empty());
  EXPECT_EQ(m2.counters().gaps, 1u);
  EXPECT_EQ(m2.counters().windows_dropped, 1u);
}

TEST(DitherMonitor, RefusesSamplesThatDoNotAdvanceInTime) {
  DitherMonitor m(DitherMonitorConfig{});
  const Eigen::Vector3d z = Eigen::Vector3d::Zero();
  m.addSample(1000, z, z);
  EXPECT_EQ(m.addSample(1000, z, z), nullptr);
  EXPECT_EQ(m.addSample(10, z, z), nullptr);
  EXPECT_EQ(m.counters().refused, 2u);
}

TEST(DitherMonitor, StuckGyroIsFlaggedWhileStillAndNotCheckedWhileMoving) {
  {
    DitherMonitor m(DitherMonitorConfig{});
    Stream s;
    s.stuck_since_s[kFirstGyroChannel + 1] = 4.0;
    const auto d = run(m, s, 8.0);
    ASSERT_EQ(d.size(), 1u);
    EXPECT_EQ(d[0].channel, kFirstGyroChannel + 1);
    EXPECT_LE(d[0].time_s, 4.5);
  }
  {
    DitherMonitor m(DitherMonitorConfig{});
    Stream s;
    s.vibration_mps2 = 0.3;  // the vehicle moves: motion-band RMS far above 0.01 m/s^2
    s.stuck_since_s[kFirstGyroChannel + 1] = 4.0;
    EXPECT_TRUE(run(m, s, 8.0).empty());
    EXPECT_EQ(m.counters().gyro_windows_skipped, m.counters().windows);
  }
}

TEST(DitherMonitor, ClearsAfterTheDitherReturns) {
  DitherMonitorConfig c;
  DitherMonitor m(c);
  Stream s;
  s.accel_line_present = {false, false, false};
  run(m, s, 1.0);
  EXPECT_TRUE(m.failed(0));
  s.accel_line_present = {true, true, true};
  Eigen::Vector3d f, w;
  for (std::int64_t k = 2400; k < 4800; ++k) {
    s.sample(static_cast<double>(k) / kRate, f, w);
    m.addSample(k * kPeriodNs, f, w);
  }
  EXPECT_FALSE(m.failed(0));
}

TEST(DitherMonitor, RejectsAnInconsistentConfigurationNamingTheField) {
  DitherMonitorConfig c;
  c.hop_samples = 1000;
  try {
    DitherMonitor m(c);
    FAIL() << "accepted hop_samples 1000";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("hop_samples"), std::string::npos) << e.what();
  }
  c = DitherMonitorConfig{};
  c.accel_band_high_hz = 5000;
  EXPECT_THROW(DitherMonitor{c}, std::invalid_argument);
}
