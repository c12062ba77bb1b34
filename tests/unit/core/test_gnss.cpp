// GNSS: Keplerian propagation, satellite selection, and the least-squares fix against DOP.
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "navbus/core/gnss/gnss_fix.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/sim/gnss_receiver.hpp"

namespace earth = navbus::core::earth;
using navbus::sim::Constellation;
using navbus::sim::KeplerElements;

TEST(Constellation, EccentricOrbitObeysKeplerAndVisViva) {
  KeplerElements k;
  k.sv_id = 3;
  k.eccentricity = 0.02;
  k.arg_perigee_rad = 0.7;
  k.mean_anomaly_rad = 0.3;
  Constellation c({k});
  const double a = k.semi_major_axis_m;
  const double period = 2 * M_PI * std::sqrt(a * a * a / earth::kGm_m3ps2);
  const auto [r0, v0] = c.eci(3, 100.0);
  const auto [r1, v1] = c.eci(3, 100.0 + period);
  EXPECT_LT((r0 - r1).norm(), 1e-4);  // back after one period (Kepler's third law)
  double rmin = 1e18, rmax = 0;
  for (int i = 0; i < 2000; ++i) {
    const auto [r, v] = c.eci(3, period * i / 2000.0);
    rmin = std::min(rmin, r.norm());
    rmax = std::max(rmax, r.norm());
    EXPECT_NEAR(v.squaredNorm(), earth::kGm_m3ps2 * (2 / r.norm() - 1 / a), 1e-3);  // vis-viva
  }
  EXPECT_NEAR(rmin, a * (1 - k.eccentricity), 50.0);
  EXPECT_NEAR(rmax, a * (1 + k.eccentricity), 50.0);
}

TEST(GnssReceiver, KeepsOnlyTheFirstEpochsBestNSatellites) {
  Constellation c(navbus::sim::ConstellationConfig{});
  navbus::sim::GnssReceiverConfig cfg;
  cfg.fixed_satellites = 4;
  navbus::sim::GnssReceiverModel rx(cfg, c);
  std::mt19937_64 rng(1);
  const Eigen::Vector3d pos = earth::geodeticToEcef({36.5 * M_PI / 180, 127.5 * M_PI / 180, 0.0});
  std::set<int> first;
  for (int k = 0; k < 20; ++k) {
    const auto e = rx.observe(static_cast<std::int64_t>(k) * 1'000'000'000, 0, pos,
                              Eigen::Vector3d::Zero(), rng);
    std::set<int> ids;
    for (const auto& s : e.satellites) ids.insert(s.sv_id);
    if (k == 0) first = ids;
    EXPECT_EQ(ids, first);
  }
  EXPECT_EQ(first.size(), 4u);
}

TEST(GnssFix, LeastSquaresErrorMatchesPdopTimesSigma) {
  // Given 3 m pseudorange noise over 200 epochs of changing geometry,
  Constellation c(navbus::sim::ConstellationConfig{});
  navbus::sim::GnssReceiverConfig cfg;
  cfg.pseudorange_sigma_m = 3.0;
  cfg.max_satellites = 8;
  navbus::sim::GnssReceiverModel rx(cfg, c);
  std::mt19937_64 rng(5);
  const earth::Geodetic site{36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  const Eigen::Vector3d pos = earth::geodeticToEcef(site);
  double sum_sq = 0.0, worst = 0.0, clock_err_sq = 0.0;
  const int n = 200;
  for (int k = 0; k < n; ++k) {
    const std::int64_t t =
        1'400'000'000'000'000'000 + static_cast<std::int64_t>(k) * 60'000'000'000;
    const auto epoch = rx.observe(t, t, pos, Eigen::Vector3d::Zero(), rng);
    const auto fix = rx.fix(epoch, site, Eigen::Vector3d::Zero(), rng);
    ASSERT_TRUE(fix.valid);
    const double err = (earth::geodeticToEcef(fix.position) - pos).norm();
    // then each error, in units of PDOP * sigma, has unit RMS (E|dr|^2 = sigma^2 trace(Q_pos)).
    const double normalized = err / (fix.pdop * cfg.pseudorange_sigma_m);
    sum_sq += normalized * normalized;
    worst = std::max(worst, normalized);
    std::vector<navbus::core::RangeObservation> obs;
    for (const auto& s : epoch.satellites) {
      obs.push_back({s.sat_pos_ecef_m, s.sat_vel_ecef_mps,
                     s.pseudorange_m + s.sat_clock_correction_m,
                     s.pseudorange_rate_mps + s.sat_clock_drift_mps});
    }
    const auto ls = navbus::core::leastSquaresFix(obs);
    clock_err_sq += std::pow(ls.clock_bias_m - cfg.clock_bias_m, 2);
    EXPECT_NEAR(ls.vel_ecef_mps.norm(), 0.0, 1.0);
  }
  EXPECT_LT(std::sqrt(clock_err_sq / n), 5 * cfg.pseudorange_sigma_m);
  const double rms = std::sqrt(sum_sq / n);
  std::printf(
      "LS fix over %d epochs: RMS error / (PDOP sigma) = %.3f, worst %.2f, clock RMS %.2f m\n", n,
      rms, worst, std::sqrt(clock_err_sq / n));
  EXPECT_NEAR(rms, 1.0, 0.15);
  EXPECT_LT(worst, 4.0);
}
