// Issue 4's targets with fixed seeds and small run counts (the full counts are the benchmark
// commands in docs/results.md): scenarios through the offline runner, errors against the truth.
#include <algorithm>
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "navbus/bus/config.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/evaluation/evaluation.hpp"
#include "navbus/evaluation/offline_runner.hpp"
#include "test_paths.hpp"

namespace evaluation = navbus::evaluation;
namespace units = navbus::units;

namespace {

const std::string kScenarios = navbus::test_paths::scenarioDir();
const std::string kConfig = navbus::test_paths::configDir();

struct Errors {
  double pos_rms{0}, vel_rms{0}, att_rms_arcsec{0}, pos_max{0}, nees{0};
  std::size_t n{0};
};

constexpr std::int64_t kStart = 1'400'000'000'000'000'000;  // the scenarios' start time

/// Runs one scenario through the offline runner with a filter configuration (both optionally
/// edited), starting at the truth or at a draw from the filter's initial sigmas.
evaluation::OfflineResult runResult(const std::string& scenario, const std::string& filter,
                                    std::uint64_t seed, double duration_s, bool perturb,
                                    const std::function<void(YAML::Node&)>& edit_filter = {},
                                    const std::function<void(YAML::Node&)>& edit_scenario = {}) {
  YAML::Node sy = YAML::Clone(navbus::bus::loadYamlFile(kScenarios + "/" + scenario));
  if (edit_scenario) edit_scenario(sy);
  YAML::Node fy = YAML::Clone(navbus::bus::loadYamlFile(kConfig + "/" + filter));
  if (edit_filter) edit_filter(fy);
  evaluation::OfflineSetup s;
  s.sim = navbus::sensor_sim::parseSimConfig(sy);
  s.sim.scenario.seed = seed;
  s.filter = navbus::nav_filter::parseFilterConfig(fy);
  s.duration_s = duration_s;
  const auto truth0 = evaluation::initialTruth(s.sim.scenario);
  s.filter.engine.initial_state =
      perturb ? evaluation::perturbedInitialState(truth0, s.filter.engine.tuning, seed * 7 + 1)
              : truth0;
  EXPECT_EQ(s.sim.scenario.start_time_ns, kStart);
  return evaluation::runOffline(s);
}

/// Error statistics of one run from `from_s` to `to_s` (relative to the start).
Errors run(const std::string& scenario, const std::string& filter, std::uint64_t seed,
           double duration_s, double from_s, double to_s, bool perturb,
           const std::function<void(YAML::Node&)>& edit_filter = {},
           const std::function<void(YAML::Node&)>& edit_scenario = {}) {
  const evaluation::OfflineResult r =
      runResult(scenario, filter, seed, duration_s, perturb, edit_filter, edit_scenario);
  const std::int64_t t0 = kStart;
  Errors e;
  for (const auto& x : r.errors) {
    const double t = 1e-9 * static_cast<double>(x.time_ns - t0);
    if (t < from_s || t > to_s) continue;
    e.pos_rms += x.pos_ned_m.squaredNorm();
    e.vel_rms += x.vel_ned_mps.squaredNorm();
    e.att_rms_arcsec += x.att_ned_rad.squaredNorm();
    e.pos_max = std::max(e.pos_max, x.pos_ned_m.norm());
    e.nees += x.nees9;
    ++e.n;
  }
  const double n = static_cast<double>(std::max<std::size_t>(e.n, 1));
  e.pos_rms = std::sqrt(e.pos_rms / n);
  e.vel_rms = std::sqrt(e.vel_rms / n);
  e.att_rms_arcsec = std::sqrt(e.att_rms_arcsec / n) * 180.0 / M_PI * 3600.0;
  e.nees /= n;
  return e;
}

}  // namespace

TEST(Targets, Seed001CentralizedMeetsTable5WhereTheStarTrackerBiasAllows) {
  // Given the LEO scenario, 400 s, the centralized three-sensor filter,
  const Errors c = run("seed001_leo.yaml", "filter_seed001_lc.yaml", 1, 400, 100, 400, true);
  // then position and velocity meet table 5 (1.331 m, 0.005 m/s);
  std::printf("seed001 centralized: pos %.3f m, vel %.4f m/s, att %.2f arcsec, NEES %.1f\n",
              c.pos_rms, c.vel_rms, c.att_rms_arcsec, c.nees);
  EXPECT_LT(c.pos_rms, 1.331);
  EXPECT_LT(c.vel_rms, 0.005);
  // the attitude follows the star tracker's 5 arcsec Gauss-Markov bias, which no filter can
  // separate from the attitude (no other attitude reference in orbit): bounded by the bias,
  // and the filter, which models the bias as states, says so (NEES of 9 states near 9, where
  // it was 140-210 without the bias states).
  EXPECT_LT(c.att_rms_arcsec, 20.0);
  EXPECT_LT(c.nees, 2 * 9.0);
  // Without that bias (and without its states) the filter reaches table 5's 0.54 arcsec and
  // is consistent.
  const Errors nb = run(
      "seed001_leo.yaml", "filter_seed001_lc.yaml", 1, 400, 100, 400, true,
      [](YAML::Node& y) { y["ekf"]["star_tracker_bias_sigma_arcsec"] = 0; },
      [](YAML::Node& y) { y["star_tracker"]["bias_arcsec"] = 0; });
  std::printf("seed001 centralized, star tracker without bias: att %.2f arcsec, NEES %.1f\n",
              nb.att_rms_arcsec, nb.nees);
  EXPECT_LT(nb.att_rms_arcsec, 0.54);
  EXPECT_LT(nb.nees, 3 * 9.0);
  // The federated structure stays close to the centralized one.
  const Errors f = run("seed001_leo.yaml", "filter_seed001_lc.yaml", 1, 400, 100, 400, true,
                       [](YAML::Node& y) { y["fusion"] = "federated"; });
  std::printf("seed001 federated: pos %.3f m, vel %.4f m/s, att %.2f arcsec\n", f.pos_rms,
              f.vel_rms, f.att_rms_arcsec);
  EXPECT_NEAR(f.pos_rms, c.pos_rms, 0.2 * c.pos_rms);
  EXPECT_NEAR(f.att_rms_arcsec, c.att_rms_arcsec, 0.2 * c.att_rms_arcsec);
}

TEST(Targets, Seed001AdaptiveResistsTheGpsPulseWhileCentralizedFollowsIt) {
  // Given the 55 m north GPS pulse at 600-620 s,
  auto with = [](const char* fusion) { return [fusion](YAML::Node& y) { y["fusion"] = fusion; }; };
  const Errors c = run("seed001_gps_pulse.yaml", "filter_seed001_lc.yaml", 1, 650, 595, 650, false,
                       with("centralized"));
  const Errors a = run("seed001_gps_pulse.yaml", "filter_seed001_lc.yaml", 1, 650, 595, 650, false,
                       with("adaptive"));
  std::printf("GPS pulse 595-650 s, max position error: centralized %.2f m, adaptive %.2f m\n",
              c.pos_max, a.pos_max);
  // then the plain centralized filter follows the fault and the adaptive one stays within 5 m.
  EXPECT_GT(c.pos_max, 5.0);
  EXPECT_LT(a.pos_max, 5.0);
}

TEST(Targets, Seed000TightlyCoupledIsConsistent) {
  // Given 8 runs of 700 s with initial errors drawn from the filter's own sigmas,
  const int runs = 8;
  double nees = 0;
  for (int i = 1; i <= runs; ++i) {
    nees += run("seed000_aircraft.yaml", "filter_seed000_tc.yaml", static_cast<std::uint64_t>(i),
                700, 100, 700, true)
                .nees;
  }
  nees /= runs;
  const double lo = evaluation::chiSquareQuantile(0.025, 9.0 * runs) / runs;
  const double hi = evaluation::chiSquareQuantile(0.975, 9.0 * runs) / runs;
  std::printf("seed000 tightly coupled, %d runs: average NEES(9) %.2f, 95%% band [%.2f, %.2f]\n",
              runs, nees, lo, hi);
  // then the average NEES lies in the 95 % chi-square band.
  EXPECT_GT(nees, lo);
  EXPECT_LT(nees, hi);
}

TEST(Targets, Seed004MultiDimensionalFilterConvergesFasterThanTheInterruptedFilter) {
  // Given the land vehicle with its two GNSS outages (50-80 s, 110-130 s) and three filters:
  // the MDF, case I (the 15-state filter interrupted in the outage, resumed as it was) and
  // case II (resumed with its covariance re-initialized),
  auto policy = [](const char* p) {
    return [p](YAML::Node& y) { y["multi_dimensional"]["policy"] = p; };
  };
  std::map<std::string, std::vector<double>> recovery;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    for (const char* p : {"mdf", "continue", "reset_all"}) {
      const evaluation::OfflineResult r = runResult(
          "seed004_land_vehicle.yaml", "filter_seed004_mdf.yaml", seed, 160, false, policy(p));
      for (double t : {80.0, 130.0}) {
        const double s = evaluation::convergenceTime(
            r.errors, kStart + static_cast<std::int64_t>(t * 1e9), 1.5, 10.0);
        recovery[p].push_back(std::isnan(s) ? 1e9 : s);  // never converged: slowest
      }
    }
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  };
  const double mdf = median(recovery["mdf"]), one = median(recovery["continue"]),
               two = median(recovery["reset_all"]);
  std::printf(
      "seed004, 5 seeds x 2 outages, median time to stay below 1.5 m for 10 s: MDF %.2f s, "
      "case I %.3g s, case II %.2f s (1e9: not within 10 s)\n",
      mdf, one, two);
  // then the MDF converges faster than case I (seed 004 fig. 7). Against case II the ordering
  // is not robust at this sample size (the closing note of issue 4 gives the 40-run figures).
  EXPECT_LT(mdf, one);
  EXPECT_LT(two, one);
}

TEST(Targets, Seed004ReducedFiltersAreConsistentWithConsiderStates) {
  // Given the land vehicle, 10 seeds, the MDF with the states a stage does not estimate
  // dropped (seed 004) or kept as consider states,
  auto average_nees = [](const char* unestimated, double from_s, double to_s,
                         const char* resets = "inflate") {
    double sum = 0.0;
    int n = 0;
    for (std::uint64_t seed = 1; seed <= 10; ++seed) {
      const evaluation::OfflineResult r =
          runResult("seed004_land_vehicle.yaml", "filter_seed004_mdf.yaml", seed, 160, false,
                    [unestimated, resets](YAML::Node& y) {
                      y["multi_dimensional"]["unestimated_states"] = unestimated;
                      y["multi_dimensional"]["resets"] = resets;
                    });
      for (const auto& e : r.errors) {
        const double t = 1e-9 * static_cast<double>(e.time_ns - kStart);
        if (t < from_s || t > to_s) continue;
        sum += e.nees9;
        ++n;
      }
    }
    return sum / std::max(n, 1);
  };
  // standing still (97-105 s) and in the first outage (60-80 s),
  const double still_drop = average_nees("drop", 97, 105);
  const double still_consider = average_nees("consider", 97, 105);
  const double outage_drop = average_nees("drop", 60, 80);
  const double outage_consider = average_nees("consider", 60, 80);
  std::printf(
      "seed004 MDF, NEES(9) over 10 seeds: standing still drop %.1f consider %.1f; "
      "outage drop %.1f consider %.1f\n",
      still_drop, still_consider, outage_drop, outage_consider);
  // then dropping them makes the filter overconfident (the tilt absorbs the horizontal
  // accelerometer biases F1 leaves out; F4's position variance is frozen), and considering
  // them keeps the NEES of 9 states near 9 (the 95 % band of 10 runs is [6.6, 11.8]; these are
  // averages over correlated epochs, so the bound is looser).
  EXPECT_GT(still_drop, 3 * 9.0);
  EXPECT_GT(outage_drop, 3 * 9.0);
  EXPECT_LT(still_consider, 1.6 * 9.0);
  EXPECT_LT(outage_consider, 1.6 * 9.0);
  // Over the whole run, the paper's filter (states dropped, eq. 12's resets zeroing every
  // correlation) against the shipped one (consider states, resets that only inflate): the
  // shipped one inside the 95 % band of 10 runs, [6.56, 11.81].
  const double paper = average_nees("drop", 0, 160, "paper");
  const double shipped = average_nees("consider", 0, 160);
  std::printf("seed004 MDF, NEES(9) over 10 seeds, whole run: paper %.1f, shipped %.1f\n", paper,
              shipped);
  EXPECT_GT(paper, 3 * 9.0);
  EXPECT_GT(shipped, 6.56);
  EXPECT_LT(shipped, 11.81);
}

TEST(ChiSquare, QuantilesMatchTables) {
  EXPECT_NEAR(evaluation::chiSquareQuantile(0.975, 9), 19.023, 0.03);
  EXPECT_NEAR(evaluation::chiSquareQuantile(0.025, 9), 2.700, 0.03);
  EXPECT_NEAR(evaluation::chiSquareQuantile(0.975, 360), 414.0, 0.5);
}

namespace {

/// One run with the filter aligning from its inputs (the configuration's initial_state
/// removed): the alignment's start against the truth, and the first solution.
struct AlignedRun {
  evaluation::OfflineResult result;
  navbus::StartSource first_source{navbus::START_CONFIGURED};
  double first_solution_s{-1};
};

AlignedRun alignedRun(const std::string& scenario, const std::string& filter, std::uint64_t seed,
                      double duration_s, double fix_velocity_sigma_mps = 0.0) {
  YAML::Node fy = YAML::Clone(navbus::bus::loadYamlFile(kConfig + "/" + filter));
  fy.remove("initial_state");
  evaluation::OfflineSetup s;
  s.sim =
      navbus::sensor_sim::parseSimConfig(navbus::bus::loadYamlFile(kScenarios + "/" + scenario));
  s.sim.scenario.seed = seed;
  if (fix_velocity_sigma_mps > 0.0) s.sim.scenario.gnss.fix_vel_sigma_mps = fix_velocity_sigma_mps;
  s.filter = navbus::nav_filter::parseFilterConfig(fy);
  s.duration_s = duration_s;
  AlignedRun run;
  run.result = evaluation::runOffline(
      s, [&](const navbus::NavigationSolution& sol, const auto&, const auto&) {
        if (run.first_solution_s >= 0) return;
        run.first_solution_s = 1e-9 * static_cast<double>(sol.time_gps_ns() - kStart);
        run.first_source = sol.start_source();
      });
  return run;
}

double alignedAt(const evaluation::OfflineResult& r) {
  return 1e-9 * static_cast<double>(r.aligned_start.state.time_ns - kStart);
}

}  // namespace

TEST(Alignment, Seed000GyrocompassesAtRestWithinItsOwnSigmas) {
  // Given the seed-000 aircraft at rest for 500 s, a navigation-grade IMU (1 deg/h, 1 mg) and
  // no configured initial state, 6 seeds,
  double normalized = 0;
  const int runs = 6;
  for (int seed = 1; seed <= runs; ++seed) {
    const AlignedRun run = alignedRun("seed000_aircraft.yaml", "filter_seed000_tc.yaml",
                                      static_cast<unsigned>(seed), 80);
    const evaluation::OfflineResult& r = run.result;
    // when the filter aligns itself,
    ASSERT_TRUE(r.aligned) << "seed " << seed << ": " << r.summary;
    // then it levels and gyrocompasses over the 60 s window at rest (the attitude source is in
    // every solution, no solution before the start),
    EXPECT_EQ(r.aligned_start.attitude_source, navbus::core::AttitudeSource::kGyrocompass);
    EXPECT_EQ(run.first_source, navbus::START_GYROCOMPASS);
    EXPECT_GE(alignedAt(r), 60.0);
    EXPECT_GT(run.first_solution_s, alignedAt(r));
    // the heading sigma it reports is the gyrocompassing limit of this gyro grade here,
    // 1 deg/h / (W cos 36.5 deg) = 82.7 mrad,
    EXPECT_NEAR(r.aligned_start.att_sigma_ned_rad.z(), 0.0827, 0.001);
    EXPECT_NEAR(r.aligned_start.gyrocompass_heading_sigma_rad, 0.0827, 0.001);
    const Eigen::Vector3d z =
        r.aligned_start_error.att_ned_rad.cwiseQuotient(r.aligned_start.att_sigma_ned_rad);
    normalized += z.squaredNorm();
    std::printf("seed %d: aligned at %.1f s, attitude error / sigma (N, E, D) %.2f %.2f %.2f\n",
                seed, alignedAt(r), z.x(), z.y(), z.z());
  }
  // and the attitude errors of the starts are consistent with those sigmas (chi-square with
  // 3 x runs degrees of freedom, 99.9 % bound).
  EXPECT_LT(normalized, evaluation::chiSquareQuantile(0.999, 3.0 * runs));
}

TEST(Alignment, Seed000MeasuresTheHeadingAgainFromTheCourseAtTakeoff) {
  // Given seed 000's seed 22, whose east gyro bias (3.3 sigma) gyrocompassing turns into a
  // heading error of 0.27 rad, and the takeoff at 501 s (20 m/s^2 for 10 s),
  const AlignedRun run = alignedRun("seed000_aircraft.yaml", "filter_seed000_tc.yaml", 22, 1000);
  const evaluation::OfflineResult& r = run.result;
  ASSERT_TRUE(r.aligned) << r.summary;
  ASSERT_GT(std::abs(r.aligned_start_error.att_ned_rad.z()), 0.2);
  // when the filter starts from that alignment, it measures the heading again from the GNSS
  // course once, at the first pseudorange epoch faster than 5 m/s,
  EXPECT_NE(r.summary.find("heading measured again from the GNSS course 1 time(s)"),
            std::string::npos)
      << r.summary;
  // and from there on the heading error is a few mrad and the tilt errors within 3 mrad
  // (without the check the first-order update turned the takeoff's (1 - cos psi) f into tilt:
  // 6.9 mrad against a sigma of 0.33);
  // the north gyro bias is freed of the Earth rate's second-order term it learned at rest
  // (0.44 deg/h; with the linear correction alone it was -0.47 deg/h off after the check and
  // -2.4 deg/h at 600 s),
  // and the attitude stays within its own covariance through level flight (chi-square, 3
  // degrees of freedom, 99.9 %; with the attitude rows of the covariance left unturned by the
  // 0.28 rad correction the roll and the y accelerometer bias were learned as if separable in
  // level flight: attitude NEES 3289 at 1000 s).
  const double nees_att_bound = evaluation::chiSquareQuantile(0.999, 3.0);
  int checked = 0;
  for (const auto& e : r.errors) {
    const double t = 1e-9 * static_cast<double>(e.time_ns - kStart);
    if (t < 505.0) continue;
    ++checked;
    EXPECT_LT(std::abs(e.att_ned_rad.z()), 0.005) << "at " << t << " s";
    EXPECT_LT(e.att_ned_rad.head<2>().cwiseAbs().maxCoeff(), 0.003) << "at " << t << " s";
    EXPECT_LT(std::abs(e.gyro_bias_err_b_radps.x()), 0.15 * units::kDegPerHour)
        << "at " << t << " s";
    EXPECT_LT(e.nees_blocks[2], nees_att_bound) << "at " << t << " s";
  }
  EXPECT_GT(checked, 4000);
}

TEST(Alignment, Seed001TakesTheAttitudeFromTheFirstStarTrackerSampleAfterTheFirstFix) {
  // Given the LEO orbit, GNSS fixes at 10 Hz and a 5 Hz star tracker, no configured state,
  const AlignedRun run = alignedRun("seed001_leo.yaml", "filter_seed001_lc.yaml", 1, 5);
  const evaluation::OfflineResult& r = run.result;
  ASSERT_TRUE(r.aligned) << r.summary;
  // then the attitude comes from the star tracker and the position from the first fix, at
  // once (the first star-tracker sample at 0.2 s),
  EXPECT_EQ(r.aligned_start.attitude_source, navbus::core::AttitudeSource::kStarTracker);
  EXPECT_EQ(r.aligned_start.position_source, navbus::core::PositionSource::kGnssFix);
  EXPECT_NEAR(alignedAt(r), 0.2, 0.01);
  EXPECT_EQ(run.first_source, navbus::START_STAR_TRACKER);
  // within 3 of the star tracker's own sigmas, and without an inertial gap at the hand-over.
  EXPECT_TRUE((r.aligned_start_error.att_ned_rad.array().abs() <=
               3.0 * r.aligned_start.att_sigma_ned_rad.array())
                  .all());
  EXPECT_NE(r.summary.find("inertial gaps 0"), std::string::npos) << r.summary;
}

TEST(Alignment, Seed004MemsLevelsAtRestAndTakesTheHeadingFromTheGnssCourse) {
  // Given the land vehicle with MEMS gyros (0.1 deg/s: no gyrocompassing), at rest for 10 s and
  // then accelerating, no configured state,
  const AlignedRun run = alignedRun("seed004_land_vehicle.yaml", "filter_seed004_mdf.yaml", 1, 30);
  const evaluation::OfflineResult& r = run.result;
  ASSERT_TRUE(r.aligned) << r.summary;
  // then the heading comes from the GNSS course once the vehicle is faster than 5 m/s, and the
  // alignment says gyrocompassing could not reach 10 deg here,
  EXPECT_EQ(r.aligned_start.attitude_source, navbus::core::AttitudeSource::kGnssCourse);
  EXPECT_EQ(run.first_source, navbus::START_GNSS_COURSE);
  EXPECT_GT(alignedAt(r), 10.0);
  EXPECT_LT(alignedAt(r), 15.0);
  EXPECT_GT(r.aligned_start.gyrocompass_heading_sigma_rad, 10.0 * M_PI / 180.0);
  EXPECT_TRUE((r.aligned_start_error.att_ned_rad.array().abs() <=
               3.0 * r.aligned_start.att_sigma_ned_rad.array())
                  .all());
}

TEST(Alignment, APositionOnlyReceiverGivesTheCourseFromTwoFixes) {
  // Given the land vehicle whose receiver's velocity is noise of 100 m/s (positions only, as
  // NMEA GGA gives them), where the fix's "course" gave a 2.8-rad heading sigma and a run 83 m
  // RMS, 276 m worst, 57 deg attitude error,
  const AlignedRun run =
      alignedRun("seed004_land_vehicle.yaml", "filter_seed004_mdf.yaml", 1, 150, 100.0);
  const evaluation::OfflineResult& r = run.result;
  ASSERT_TRUE(r.aligned) << r.summary;
  // then the course comes from the chord between two fixes on a straight stretch, the
  // alignment waits until its heading sigma is below the 10-deg limit,
  EXPECT_EQ(r.aligned_start.attitude_source, navbus::core::AttitudeSource::kGnssCourse);
  EXPECT_LT(r.aligned_start.att_sigma_ned_rad.z(), 10.0 * M_PI / 180.0);
  EXPECT_TRUE((r.aligned_start_error.att_ned_rad.array().abs() <=
               3.0 * r.aligned_start.att_sigma_ned_rad.array())
                  .all());
  // the start's velocity is the chord's, not the fix's noise,
  EXPECT_LT(r.aligned_start_error.vel_ned_mps.head<2>().norm(),
            3.0 * r.aligned_start.vel_sigma_ned_mps.head<2>().norm());
  EXPECT_LT(r.aligned_start.vel_sigma_ned_mps.x(), 5.0);
  // and the run stays within metres (measured 8.3 m RMS, 25 m worst, 4.2 deg).
  double squares = 0.0, worst = 0.0, worst_att = 0.0;
  for (const auto& e : r.errors) {
    squares += e.pos_ned_m.squaredNorm();
    worst = std::max(worst, e.pos_ned_m.norm());
    worst_att = std::max(worst_att, e.att_ned_rad.norm());
  }
  const double rms = std::sqrt(squares / static_cast<double>(r.errors.size()));
  std::printf(
      "position-only alignment: heading sigma %.1f mrad, run %.1f m RMS, %.1f m worst, "
      "%.1f deg worst attitude\n",
      1e3 * r.aligned_start.att_sigma_ned_rad.z(), rms, worst, worst_att / M_PI * 180.0);
  EXPECT_LT(rms, 12.0);
  EXPECT_LT(worst, 40.0);
  EXPECT_LT(worst_att, 8.0 * M_PI / 180.0);
}
