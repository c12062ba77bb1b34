// Closed loop on the seed-000 scenario: the tightly coupled EKF fed by the simulator.
#include <cmath>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/core/filter/integrated_filter.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "test_paths.hpp"

namespace earth = navbus::core::earth;
namespace layout = navbus::core::layout;

namespace {
struct RunResult {
  double pos_err_m, vel_err_mps, att_err_rad;
  double pos_sigma_m;
  double mean_nees;  ///< position + velocity + attitude (9 dof), averaged over GNSS epochs
  int epochs, rejected;
  double mean_position_nees;  ///< position only (3 dof), averaged over the GNSS epochs
};

/// Time-correlated pseudorange errors added to the simulator's white ones: each satellite's a
/// first-order Gauss-Markov process, modelled by the filter or not.
struct CorrelatedRangeErrors {
  double sigma_m{0.0};  ///< 0: none added
  double correlation_time_s{600.0};
  bool modelled{false};
};

RunResult run(double seconds, std::uint64_t seed, const CorrelatedRangeErrors& ce = {}) {
  auto c = navbus::sensor_sim::parseSimConfig(
               navbus::bus::loadYamlFile(std::string(navbus::test_paths::scenarioDir()) +
                                         "/seed000_aircraft.yaml"))
               .scenario;
  c.seed = seed;
  navbus::sim::ScenarioSource src(c);
  navbus::core::FilterTuning cfg;
  cfg.accel_noise_mps2_per_sqrthz = 10e-6 * 9.80665;
  cfg.gyro_noise_radps_per_sqrthz = 0.001 * M_PI / 180 / 60;
  cfg.accel_bias_sigma_mps2 = 1000e-6 * 9.80665;
  cfg.gyro_bias_sigma_radps = 1.0 * M_PI / 180 / 3600;
  cfg.clock_bias_noise_m_per_sqrts = c.gnss.clock_bias_noise_m_per_sqrts;
  cfg.clock_drift_noise_mps_per_sqrts = c.gnss.clock_drift_noise_mps_per_sqrts;
  if (ce.modelled) {
    cfg.pseudorange_error_sigma_m = ce.sigma_m;
    cfg.pseudorange_error_correlation_time_s = ce.correlation_time_s;
  }
  std::map<int, double> range_error_m;  // per satellite
  std::mt19937_64 range_rng(seed + 200);
  double last_epoch_s = 0.0;
  // Initial errors drawn from the paper's budget: 40 m, 1 m/s, 1 mrad level, 5 mrad heading.
  std::mt19937_64 rng(seed + 100);
  std::normal_distribution<double> n(0.0, 1.0);
  navbus::core::NavState truth0;
  truth0.position = c.vehicle.position;
  truth0.q_b_to_n = Eigen::Quaterniond(navbus::core::dcmFromEuler(c.vehicle.roll_pitch_yaw_rad));
  navbus::core::NavState s0 = truth0;
  const earth::Radii r = earth::radiiOfCurvature(s0.position.latitude_rad);
  s0.position.latitude_rad += 40.0 * n(rng) / r.meridian_m;
  s0.position.longitude_rad +=
      40.0 * n(rng) / (r.prime_vertical_m * std::cos(s0.position.latitude_rad));
  s0.position.height_m += 40.0 * n(rng);
  s0.vel_ned_mps = Eigen::Vector3d(n(rng), n(rng), n(rng));
  s0.q_b_to_n = navbus::core::quaternionFromRotationVector(
                    Eigen::Vector3d(1e-3 * n(rng), 1e-3 * n(rng), 5e-3 * n(rng))) *
                s0.q_b_to_n;
  s0.time_ns = c.start_time_ns;
  navbus::core::IntegratedFilter ekf;
  ekf.initialize(s0, 0.0, 0.0, cfg, ~navbus::core::StateMask());
  RunResult res{};
  double nees_sum = 0, position_nees_sum = 0;
  const auto steps = static_cast<long>(seconds * 100);
  navbus::sim::SensorFrame f;
  for (long k = 0; k < steps; ++k) {
    f = src.next();
    ekf.propagate(f.increment);
    if (!f.has_gnss) continue;
    std::vector<navbus::core::SatelliteObservation> sats;
    const double now_s = 0.01 * static_cast<double>(k);
    const double decay = std::exp(-(now_s - last_epoch_s) / ce.correlation_time_s);
    last_epoch_s = now_s;
    for (const auto& m : f.gnss.satellites) {
      double error_m = 0.0;
      if (ce.sigma_m > 0.0) {
        const auto [it, fresh] = range_error_m.try_emplace(m.sv_id, ce.sigma_m * n(range_rng));
        if (!fresh)
          it->second =
              decay * it->second + std::sqrt(1.0 - decay * decay) * ce.sigma_m * n(range_rng);
        error_m = it->second;
      }
      sats.push_back({m.sv_id, m.sat_pos_ecef_m, m.sat_vel_ecef_mps,
                      m.pseudorange_m + m.sat_clock_correction_m + error_m,
                      m.pseudorange_rate_mps + m.sat_clock_drift_mps, m.pseudorange_sigma_m,
                      m.pseudorange_rate_sigma_mps});
    }
    for (const auto& rep : ekf.update(sats)) res.rejected += rep.result.accepted ? 0 : 1;
    // The GLR diagnostics: two rows per satellite, symmetric positive definite V, K = P H^T V^-1.
    const auto& diag = ekf.lastEpoch();
    EXPECT_EQ(diag.h.rows(), static_cast<Eigen::Index>(2 * sats.size()));
    EXPECT_LT((diag.innovation_cov - diag.innovation_cov.transpose()).norm(),
              1e-6 * diag.innovation_cov.norm());
    EXPECT_EQ(diag.k.cols(), diag.h.rows());
    ++res.epochs;
    // NEES of position, velocity and attitude against the truth.
    const auto& e = ekf.state();
    const auto& t = f.truth;
    Eigen::Matrix<double, 9, 1> d;
    const earth::Radii rr = earth::radiiOfCurvature(t.position.latitude_rad);
    d[0] =
        (e.position.latitude_rad - t.position.latitude_rad) * (rr.meridian_m + t.position.height_m);
    d[1] = (e.position.longitude_rad - t.position.longitude_rad) *
           (rr.prime_vertical_m + t.position.height_m) * std::cos(t.position.latitude_rad);
    d[2] = -(e.position.height_m - t.position.height_m);
    d.segment<3>(3) = e.vel_ned_mps - t.vel_ned_mps;
    const Eigen::Matrix3d M =
        e.q_b_to_n.toRotationMatrix() * t.q_b_to_n.toRotationMatrix().transpose();
    d.segment<3>(6) =
        Eigen::Vector3d(M(1, 2) - M(2, 1), M(2, 0) - M(0, 2), M(0, 1) - M(1, 0)) / 2.0;
    const Eigen::Matrix<double, 9, 9> P9 = ekf.covariance().topLeftCorner<9, 9>();
    nees_sum += d.dot(P9.ldlt().solve(d));
    const Eigen::Vector3d dp = d.head<3>();
    position_nees_sum += dp.dot(P9.topLeftCorner<3, 3>().ldlt().solve(dp));
    res.pos_err_m = d.head<3>().norm();
    res.vel_err_mps = d.segment<3>(3).norm();
    res.att_err_rad = d.segment<3>(6).norm();
    res.pos_sigma_m = std::sqrt(P9.topLeftCorner<3, 3>().trace());
  }
  res.mean_nees = nees_sum / res.epochs;
  res.mean_position_nees = position_nees_sum / res.epochs;
  return res;
}
}  // namespace

TEST(IntegratedFilter, Seed000ClosedLoopTracksTheTruthConsistently) {
  for (std::uint64_t seed : {1u, 2u}) {
    const RunResult r = run(700.0, seed);
    std::printf(
        "seed %llu, 700 s: position error %.2f m (reported 1-sigma %.2f m), velocity %.3f m/s, "
        "attitude %.2e "
        "rad, mean NEES(9) %.2f, %d epochs, %d rows gated\n",
        static_cast<unsigned long long>(seed), r.pos_err_m, r.pos_sigma_m, r.vel_err_mps,
        r.att_err_rad, r.mean_nees, r.epochs, r.rejected);
    EXPECT_LT(r.pos_err_m, 3.0 * r.pos_sigma_m + 1.0);
    EXPECT_EQ(r.rejected, 0);
    // A single run's time-averaged NEES is only a coarse check (the 40-run band is issue 4's
    // target); this bound catches a filter that is badly overconfident.
    EXPECT_LT(r.mean_nees, 3.0 * 9);
  }
}

TEST(IntegratedFilter, PseudorangeErrorStatesKeepTheCovarianceHonestUnderCorrelatedErrors) {
  // Seed 000's 4 satellites (25 m white sigma) with 5 m errors per satellite lasting 10
  // minutes: fused as white noise they average into a position outside its covariance; as
  // Gauss-Markov states the covariance holds them. One run's time-averaged NEES is one draw of
  // slowly changing errors, so the check is the mean over 6 runs (measured over seeds 3-10:
  // 18.2 white, 3.7 as states; a consistent filter gives 3).
  double white_sum = 0.0, modelled_sum = 0.0;
  const std::vector<std::uint64_t> seeds{3, 4, 5, 6, 7, 8};
  for (const std::uint64_t seed : seeds) {
    const RunResult white = run(300.0, seed, {5.0, 600.0, false});
    const RunResult modelled = run(300.0, seed, {5.0, 600.0, true});
    std::printf(
        "seed %llu, 300 s, 5 m / 600 s range errors: mean position NEES(3) %.1f as white "
        "noise (error %.2f m, 1-sigma %.2f m), %.2f as states (error %.2f m, 1-sigma %.2f "
        "m)\n",
        static_cast<unsigned long long>(seed), white.mean_position_nees, white.pos_err_m,
        white.pos_sigma_m, modelled.mean_position_nees, modelled.pos_err_m, modelled.pos_sigma_m);
    white_sum += white.mean_position_nees;
    modelled_sum += modelled.mean_position_nees;
    EXPECT_GT(modelled.pos_sigma_m, 2.0 * white.pos_sigma_m);
    EXPECT_EQ(modelled.rejected, 0);
  }
  const double n = static_cast<double>(seeds.size());
  std::printf("mean over %zu runs: position NEES(3) %.2f as white noise, %.2f as states\n",
              seeds.size(), white_sum / n, modelled_sum / n);
  EXPECT_GT(white_sum / n, 3.0 * 3);
  EXPECT_GT(modelled_sum / n, 1.0);
  EXPECT_LT(modelled_sum / n, 2.0 * 3);
}

#include "navbus/core/filter/aiding_measurements.hpp"

TEST(AidingMeasurements, InnovationsEqualHTimesTheConstructedError) {
  navbus::core::NavState truth;
  truth.time_ns = 1'400'000'000'000'000'000;
  truth.position = {34.0 * M_PI / 180, 128.0 * M_PI / 180, 500e3};
  truth.vel_ned_mps = Eigen::Vector3d(6000.0, 4000.0, 10.0);
  truth.q_b_to_n = Eigen::Quaterniond(navbus::core::dcmFromEuler(Eigen::Vector3d(0.3, -0.2, 1.1)));
  Eigen::Matrix<double, layout::kSize, 1> dx = Eigen::Matrix<double, layout::kSize, 1>::Zero();
  dx.segment<3>(layout::kPos.index) << 12.0, -7.0, 4.0;
  dx.segment<3>(layout::kVel.index) << 0.2, -0.1, 0.05;
  dx.segment<3>(layout::kAtt.index) << 2e-5, -3e-5, 5e-5;
  navbus::core::NavState ins = truth;
  const earth::Radii r = earth::radiiOfCurvature(truth.position.latitude_rad);
  ins.position.latitude_rad += dx[0] / (r.meridian_m + truth.position.height_m);
  ins.position.longitude_rad += dx[1] / ((r.prime_vertical_m + truth.position.height_m) *
                                         std::cos(truth.position.latitude_rad));
  ins.position.height_m -= dx[2];
  ins.vel_ned_mps += dx.segment<3>(layout::kVel.index);
  ins.q_b_to_n = navbus::core::quaternionFromRotationVector(-dx.segment<3>(layout::kAtt.index)) *
                 truth.q_b_to_n;
  const Eigen::Vector3d one(1, 1, 1);
  const auto p = navbus::core::positionMeasurement(ins, truth.position, one);
  // Second order: the INS's radii and latitude differ from the truth's by the error itself.
  EXPECT_LT((p.z - p.h * dx).norm(), 1e-4);
  const auto v = navbus::core::velocityMeasurement(ins, truth.vel_ned_mps, one);
  EXPECT_LT((v.z - v.h * dx).norm(), 1e-12);
  // The star tracker measures the true attitude in ECI.
  const Eigen::Matrix3d C_e_i = earth::C_i_e(1e-9 * static_cast<double>(truth.time_ns)).transpose();
  const Eigen::Quaterniond q_b_i(
      C_e_i * earth::C_n_e(truth.position.latitude_rad, truth.position.longitude_rad) *
      truth.q_b_to_n.toRotationMatrix());
  navbus::core::NavState ins_att = truth;
  ins_att.q_b_to_n = ins.q_b_to_n;
  const auto a =
      navbus::core::attitudeMeasurement(ins_att, q_b_i, one * 1e-6, Eigen::Vector3d::Zero());
  EXPECT_LT((a.z - a.h * dx).norm(), 1e-9);
  EXPECT_NEAR(a.r.trace(), 3e-12, 1e-20);  // a rotation keeps the total variance
  // A tracker with bias b (measuring q_true exp(b), as the simulator's does) and a filter
  // estimate b^: the bias error state b^ - b enters through H as well.
  const Eigen::Vector3d b(2e-5, -3e-5, 1.5e-5);
  const Eigen::Vector3d b_est(0.5e-5, 1e-5, -1e-5);
  const Eigen::Quaterniond q_biased = q_b_i * navbus::core::quaternionFromRotationVector(b);
  const auto ab = navbus::core::attitudeMeasurement(ins_att, q_biased, one * 1e-6, b_est);
  Eigen::Matrix<double, layout::kSize, 1> dxb = dx;
  dxb.segment<3>(layout::kStarTrackerBias.index) = b_est - b;
  EXPECT_LT((ab.z - ab.h * dxb).norm(), 1e-8);  // second order in the 3e-5 rad rotations
  EXPECT_GT((ab.z - ab.h * dx).norm(), 1e-5);   // the bias term matters
}

TEST(IntegratedFilter, Seed001LooselyCoupledWithStarTrackerConverges) {
  // Seed 001's LEO with its tactical IMU, GNSS fixes and star tracker, 600 s, centralized.
  auto c = navbus::sensor_sim::parseSimConfig(
               navbus::bus::loadYamlFile(std::string(navbus::test_paths::scenarioDir()) +
                                         "/seed001_leo.yaml"))
               .scenario;
  navbus::sim::ScenarioSource src(c);
  navbus::sim::SensorFrame f = src.next();
  navbus::core::FilterTuning cfg;
  cfg.gravity = c.gravity;
  cfg.accel_noise_mps2_per_sqrthz = c.imu.accel.random_walk;
  cfg.gyro_noise_radps_per_sqrthz = c.imu.gyro.random_walk;
  cfg.accel_bias_sigma_mps2 = 100e-6 * 9.80665;
  cfg.gyro_bias_sigma_radps = 0.01 * M_PI / 180 / 3600;
  cfg.pos_sigma_m = 5.0;
  cfg.vel_sigma_mps = 0.2;
  cfg.level_sigma_rad = cfg.heading_sigma_rad = 1e-4;
  navbus::core::NavState s0 = f.truth;
  s0.position.height_m += 3.0;
  s0.vel_ned_mps += Eigen::Vector3d(0.1, -0.1, 0.05);
  s0.q_b_to_n =
      navbus::core::quaternionFromRotationVector(Eigen::Vector3d(5e-5, -5e-5, 8e-5)) * s0.q_b_to_n;
  navbus::core::IntegratedFilter ekf;
  ekf.initialize(s0, 0.0, 0.0, cfg,
                 navbus::core::maskOf({layout::kPos, layout::kVel, layout::kAtt, layout::kAccelBias,
                                       layout::kGyroBias}));
  double sum_pos = 0, sum_vel = 0, sum_att = 0;
  int n = 0;
  for (int k = 1; k < 200 * 600; ++k) {
    f = src.next();
    ekf.propagate(f.increment);
    if (f.has_gnss) {
      ekf.update(
          navbus::core::positionMeasurement(ekf.state(), f.fix.position, f.fix.pos_sigma_ned_m),
          navbus::core::AidingKind::kPosition);
      ekf.update(navbus::core::velocityMeasurement(ekf.state(), f.fix.vel_ned_mps,
                                                   f.fix.vel_sigma_ned_mps),
                 navbus::core::AidingKind::kVelocity);
    }
    if (f.has_star_tracker) {
      ekf.update(
          navbus::core::attitudeMeasurement(ekf.state(), f.star_tracker.q_b_to_i,
                                            f.star_tracker.sigma_b_rad, ekf.starTrackerBias()),
          navbus::core::AidingKind::kAttitude);
    }
    if (k % 200 == 0 && k > 200 * 100) {  // RMS after 100 s of convergence, once per second
      const auto& e = ekf.state();
      const auto& t = f.truth;
      const Eigen::Vector3d dp =
          earth::geodeticToEcef(e.position) - earth::geodeticToEcef(t.position);
      const Eigen::AngleAxisd da(e.q_b_to_n * t.q_b_to_n.conjugate());
      sum_pos += dp.squaredNorm();
      sum_vel += (e.vel_ned_mps - t.vel_ned_mps).squaredNorm();
      sum_att += da.angle() * da.angle();
      ++n;
    }
  }
  const double pos = std::sqrt(sum_pos / n), vel = std::sqrt(sum_vel / n);
  const double att_arcsec = std::sqrt(sum_att / n) * 180 / M_PI * 3600;
  std::printf(
      "seed 001 centralized (LC GNSS + star tracker), 100-600 s RMS: position %.3f m, velocity "
      "%.4f m/s, "
      "attitude %.2f arcsec (paper table 5 over 3600 s: 1.331 m, 0.005 m/s, 0.54 arcsec)\n",
      pos, vel, att_arcsec);
  EXPECT_LT(pos, 3.0);
  EXPECT_LT(vel, 0.1);
  // The star tracker's 5 arcsec-per-axis Gauss-Markov bias (8.7 arcsec in all) is not a state
  // of this filter, so the attitude follows it: bounded here, the paper's 0.54 arcsec needs the
  // bias estimated (issue 4).
  EXPECT_LT(att_arcsec, 20.0);
}
