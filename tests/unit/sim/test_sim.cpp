// The stationary source's physics: constellation geometry, pseudoranges, raw/increment
// consistency.
#include <cmath>

#include <gtest/gtest.h>

#include "navbus/core/math/earth.hpp"
#include "navbus/sim/scenario_source.hpp"

namespace earth = navbus::core::earth;

TEST(Constellation, CircularOrbitsFollowKeplersLaw) {
  navbus::sim::Constellation c(navbus::sim::ConstellationConfig{});
  const double period = 2 * M_PI * std::sqrt(std::pow(26'559'700.0, 3) / earth::kGm_m3ps2);
  EXPECT_NEAR(period, 43082.0, 5.0);  // half a sidereal day
  // In ECI the satellite returns after one period; in ECEF it is rotated by the Earth.
  const auto a = c.state(7, 0.0);
  const auto b = c.state(7, period);
  const Eigen::Vector3d a_i = earth::C_i_e(0.0).transpose() * a.pos_ecef_m;
  const Eigen::Vector3d b_i = earth::C_i_e(period).transpose() * b.pos_ecef_m;
  EXPECT_LT((a_i - b_i).norm(), 1e-3);
  EXPECT_NEAR(a.pos_ecef_m.norm(), 26'559'700.0, 1e-3);
}

TEST(GnssReceiver, PseudorangesAreRangePlusClockAndRespectTheMask) {
  navbus::sim::ScenarioConfig cfg;
  cfg.vehicle.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  cfg.gnss.pseudorange_sigma_m = 1e-3;
  cfg.gnss.pseudorange_rate_sigma_mps = 1e-4;
  cfg.gnss.elevation_mask_rad = 10.0 * M_PI / 180;
  cfg.gnss.max_satellites = 32;
  cfg.gnss_every_n_increments = 1;
  navbus::sim::ScenarioSource src(cfg);
  const auto f = src.next();
  ASSERT_TRUE(f.has_gnss);
  ASSERT_GE(f.gnss.satellites.size(), 4u);
  const Eigen::Vector3d rx = earth::geodeticToEcef(cfg.vehicle.position);
  bool any_clock = false;
  for (const auto& s : f.gnss.satellites) {
    any_clock = any_clock || std::abs(s.sat_clock_correction_m) > 100.0;
    EXPECT_GE(s.elevation_rad, cfg.gnss.elevation_mask_rad);
    const double range = (s.sat_pos_ecef_m - rx).norm();
    EXPECT_NEAR(s.pseudorange_m + s.sat_clock_correction_m - range,
                cfg.gnss.clock_bias_m + cfg.gnss.clock_drift_mps * 0.01, 0.01);
  }
  EXPECT_TRUE(any_clock);  // satellite clocks are modelled and carried as corrections
}

TEST(ScenarioSource, RawSamplesSumToTheIncrement) {
  navbus::sim::ScenarioConfig cfg;
  cfg.imu.accel.random_walk = 1e-4;
  cfg.imu.gyro.random_walk = 1e-5;
  navbus::sim::ScenarioSource src(cfg);
  const auto f = src.next();
  Eigen::Vector3d dv = Eigen::Vector3d::Zero();
  for (const auto& s : f.raw.samples) dv += s.specific_force_b_mps2 * f.raw.sample_period_s;
  EXPECT_TRUE(dv.isApprox(f.increment.delta_vel_b_mps, 1e-12));
  EXPECT_EQ(f.raw.samples.size(), 24u);
  // Same seed, same data.
  navbus::sim::ScenarioSource again(cfg);
  EXPECT_EQ(again.next().increment.delta_vel_b_mps, f.increment.delta_vel_b_mps);
}
