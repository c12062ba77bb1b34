// Static coarse alignment: exact recovery of the attitude from error-free increments, the error
// budget against injected sensor errors, and the gyro grades that cannot gyrocompass.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "navbus/core/engine/initial_alignment.hpp"
#include "navbus/core/ins/static_alignment.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"

namespace core = navbus::core;
namespace earth = navbus::core::earth;
namespace units = navbus::units;

namespace {

constexpr double kLatitude_rad = 45.0 * units::kDeg;
constexpr double kDt_s = 0.01;
constexpr int kIncrements = 6000;  // 60 s at rest

/// A navigation-grade budget (0.01 deg/h, 25 ug).
core::AlignmentErrorBudget navigationGrade() {
  core::AlignmentErrorBudget b;
  b.accel_bias_sigma_mps2 = 25 * units::kMicroG;
  b.gyro_bias_sigma_radps = 0.01 * units::kDegPerHour;
  b.velocity_random_walk_mps_per_sqrts = 1e-4;
  b.angle_random_walk_rad_per_sqrts = 0.002 * units::kDeg / 60.0;  // 0.002 deg/sqrt(h)
  return b;
}

/// A window of increments at rest with attitude rpy, plus constant sensor errors (body).
/// With `noise`, white noise of the budget's densities on every increment.
core::StaticWindow atRest(const Eigen::Vector3d& rpy_rad, const Eigen::Vector3d& accel_error_mps2,
                          const Eigen::Vector3d& gyro_error_radps, std::mt19937_64* noise = nullptr,
                          const core::AlignmentErrorBudget& budget = {}) {
  std::normal_distribution<double> unit(0.0, 1.0);
  auto white = [&](double density) -> Eigen::Vector3d {
    if (noise == nullptr) return Eigen::Vector3d::Zero();
    const double sigma = density * std::sqrt(kDt_s);  // of one increment's integral
    return Eigen::Vector3d(unit(*noise), unit(*noise), unit(*noise)) * sigma;
  };
  const Eigen::Matrix3d C_n_b = core::dcmFromEuler(rpy_rad).transpose();
  const double g = earth::normalGravity(kLatitude_rad, 0.0);
  const Eigen::Vector3d f_b = C_n_b * Eigen::Vector3d(0, 0, -g) + accel_error_mps2;
  const Eigen::Vector3d w_b = C_n_b * earth::omegaIeNed(kLatitude_rad) + gyro_error_radps;
  core::StaticWindow w;
  for (int i = 0; i < kIncrements; ++i) {
    core::ImuIncrement inc;
    inc.time_ns = (i + 1) * 10'000'000LL;
    inc.interval_s = kDt_s;
    inc.delta_vel_b_mps = f_b * kDt_s + white(budget.velocity_random_walk_mps_per_sqrts);
    inc.delta_angle_b_rad = w_b * kDt_s + white(budget.angle_random_walk_rad_per_sqrts);
    w.add(inc);
  }
  return w;
}

double wrapPi(double a) {
  return std::atan2(std::sin(a), std::cos(a));
}

}  // namespace

TEST(StaticAlignment, RecoversTheAttitudeFromErrorFreeIncrements) {
  const double g = earth::normalGravity(kLatitude_rad, 0.0);
  for (const Eigen::Vector3d& rpy_deg :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, -3, 123), Eigen::Vector3d(-10, 5, -170),
        Eigen::Vector3d(1, 1, 359)}) {
    const Eigen::Vector3d rpy = rpy_deg * units::kDeg;
    const core::CoarseAlignment a =
        core::alignStatic(atRest(rpy, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()),
                          kLatitude_rad, g, navigationGrade(), 1.0 * units::kDeg);
    ASSERT_TRUE(a.hasHeading());
    EXPECT_NEAR(a.roll_pitch_yaw_rad.x(), rpy.x(), 1e-9);
    EXPECT_NEAR(a.roll_pitch_yaw_rad.y(), rpy.y(), 1e-9);
    EXPECT_NEAR(wrapPi(a.roll_pitch_yaw_rad.z() - rpy.z()), 0.0, 1e-9);
    const Eigen::Matrix3d truth = core::dcmFromEuler(rpy);
    EXPECT_LT((a.q_b_to_n.toRotationMatrix() - truth).norm(), 1e-9);
  }
}

TEST(StaticAlignment, ErrorsFollowTheBudgetToFirstOrder) {
  const double g = earth::normalGravity(kLatitude_rad, 0.0);
  const core::AlignmentErrorBudget budget = navigationGrade();
  // Level, heading north: body x north, y east. An accelerometer error on x is a pitch error
  // b/g; a gyro error on y (east) is a heading error -b / (W cos L) (derivation step 7).
  const double ba = budget.accel_bias_sigma_mps2;
  const double bg = budget.gyro_bias_sigma_radps;
  const core::CoarseAlignment a = core::alignStatic(
      atRest(Eigen::Vector3d::Zero(), Eigen::Vector3d(ba, 0, 0), Eigen::Vector3d(0, bg, 0)),
      kLatitude_rad, g, budget, 1.0 * units::kDeg);
  ASSERT_TRUE(a.hasHeading());
  EXPECT_NEAR(a.roll_pitch_yaw_rad.y(), ba / g, 1e-3 * ba / g);
  const double horizontal_rate = earth::kRotationRate_radps * std::cos(kLatitude_rad);
  EXPECT_NEAR(a.roll_pitch_yaw_rad.z(), -bg / horizontal_rate, 1e-3 * bg / horizontal_rate);
  // The sigmas: steps 6 and 7 written out for this budget and 60 s.
  const double T = kIncrements * kDt_s;
  const double vrw = budget.velocity_random_walk_mps_per_sqrts;
  const double arw = budget.angle_random_walk_rad_per_sqrts;
  const double level = std::sqrt(ba * ba + vrw * vrw / T) / g;
  EXPECT_NEAR(a.level_sigma_rad, level, 1e-12);
  const double rate = (bg * bg + arw * arw / T) / (horizontal_rate * horizontal_rate);
  const double heading =
      std::sqrt(rate + rate * rate + std::pow(level * std::tan(kLatitude_rad), 2));
  EXPECT_NEAR(a.heading_sigma_rad, heading, 1e-12);
}

TEST(StaticAlignment, ErrorsDrawnFromTheBudgetAreConsistentWithItsSigmas) {
  // Biases drawn from the budget and white noise of its densities on every increment: the
  // normalized errors have unit mean square (400 trials: 3 sigma band [0.79, 1.21]).
  const double g = earth::normalGravity(kLatitude_rad, 0.0);
  const core::AlignmentErrorBudget budget = navigationGrade();
  std::mt19937_64 rng(20261124);
  std::normal_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d rpy = Eigen::Vector3d(3, -2, 47) * units::kDeg;
  constexpr int kTrials = 400;
  double heading_sq = 0.0;
  double level_sq = 0.0;
  for (int i = 0; i < kTrials; ++i) {
    const Eigen::Vector3d ba(unit(rng), unit(rng), unit(rng));
    const Eigen::Vector3d bg(unit(rng), unit(rng), unit(rng));
    const core::CoarseAlignment a =
        core::alignStatic(atRest(rpy, ba * budget.accel_bias_sigma_mps2,
                                 bg * budget.gyro_bias_sigma_radps, &rng, budget),
                          kLatitude_rad, g, budget, 1.0 * units::kDeg);
    const double e_heading = wrapPi(a.roll_pitch_yaw_rad.z() - rpy.z()) / a.heading_sigma_rad;
    const double e_roll = (a.roll_pitch_yaw_rad.x() - rpy.x()) / a.level_sigma_rad;
    heading_sq += e_heading * e_heading;
    level_sq += e_roll * e_roll;
  }
  EXPECT_GT(heading_sq / kTrials, 0.79);
  EXPECT_LT(heading_sq / kTrials, 1.21);
  EXPECT_GT(level_sq / kTrials, 0.79);
  EXPECT_LT(level_sq / kTrials, 1.21);
}

TEST(StaticAlignment, EarthRateMismatchRemainderIsTheExactRotationLessItsFirstOrder) {
  // Given the Earth rate at 45 deg and heading errors from small to 0.5 rad,
  const Eigen::Vector3d w_ie_ned = earth::omegaIeNed(kLatitude_rad);
  for (const double psi : {-0.5, -0.27, 0.01, 0.1, 0.27, 0.5}) {
    // the remainder (step 9) is exp(-[phi x]) w - w + phi x w, computed with Eigen's rotation,
    const Eigen::Vector3d phi(0.0, 0.0, psi);
    const Eigen::Vector3d exact = Eigen::AngleAxisd(-psi, Eigen::Vector3d::UnitZ()) * w_ie_ned -
                                  w_ie_ned + phi.cross(w_ie_ned);
    const core::EarthRateMismatch m = core::earthRateMismatchRemainder(psi, w_ie_ned);
    EXPECT_LT((m.remainder_radps - exact).norm(), 1e-18) << "psi " << psi;
    // and its derivative matches a central difference.
    constexpr double kStep = 1e-6;
    const Eigen::Vector3d numeric =
        (core::earthRateMismatchRemainder(psi + kStep, w_ie_ned).remainder_radps -
         core::earthRateMismatchRemainder(psi - kStep, w_ie_ned).remainder_radps) /
        (2.0 * kStep);
    EXPECT_LT((m.d_remainder_d_psi - numeric).norm(), 1e-14) << "psi " << psi;
  }
  // At seed 000's 3-sigma heading (0.27 rad, 36.5 deg) the north term is 0.44 deg/h.
  const core::EarthRateMismatch seed000 =
      core::earthRateMismatchRemainder(0.27, earth::omegaIeNed(36.5 * units::kDeg));
  EXPECT_NEAR(seed000.remainder_radps.x() / units::kDegPerHour, -0.44, 0.01);
}

TEST(StaticAlignment, EarthRateRemainderVarianceMatchesAQuadratureOverTheHeadingError) {
  // Given the Earth rate at 45 deg and Gaussian heading errors of several sigmas,
  const Eigen::Vector3d w_ie_ned = earth::omegaIeNed(kLatitude_rad);
  for (const double sigma : {0.01, 0.083, 0.3}) {
    // the variance of step 9's north term, integrated over psi ~ N(0, sigma^2) (trapezoids over
    // +-8 sigma), equals step 10.
    constexpr int kSteps = 20000;
    const double h = 16.0 * sigma / kSteps;
    double mean = 0.0, second = 0.0;
    for (int i = 0; i <= kSteps; ++i) {
      const double psi = -8.0 * sigma + i * h;
      const double weight = (i == 0 || i == kSteps ? 0.5 : 1.0) * h *
                            std::exp(-0.5 * psi * psi / (sigma * sigma)) /
                            (sigma * std::sqrt(2.0 * M_PI));
      const double north = core::earthRateMismatchRemainder(psi, w_ie_ned).remainder_radps.x();
      mean += weight * north;
      second += weight * north * north;
    }
    const double variance = second - mean * mean;
    EXPECT_NEAR(core::earthRateRemainderNorthVariance(sigma * sigma, w_ie_ned), variance,
                1e-6 * variance)
        << "sigma " << sigma;
  }
}

TEST(StaticAlignment, MemsGyrosCannotGyrocompassAndSaySo) {
  const double g = earth::normalGravity(kLatitude_rad, 0.0);
  core::AlignmentErrorBudget mems;
  mems.accel_bias_sigma_mps2 = 5 * units::kMilliG;
  mems.gyro_bias_sigma_radps = 10 * units::kDegPerHour;
  const Eigen::Vector3d rpy = Eigen::Vector3d(1, 2, 80) * units::kDeg;
  const core::CoarseAlignment a =
      core::alignStatic(atRest(rpy, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()),
                        kLatitude_rad, g, mems, 5.0 * units::kDeg);
  EXPECT_FALSE(a.hasHeading());
  EXPECT_EQ(a.heading_limit, core::HeadingLimit::kGyroGrade);
  // 10 deg/h against 15.04 cos 45 deg/h of horizontal Earth rate: r = 0.94^2 rad^2 to first
  // order, sqrt(r + r^2) = 1.29 rad with the second order of (7).
  const double r = std::pow(10.0 / (15.041 * std::cos(kLatitude_rad)), 2);
  EXPECT_NEAR(a.heading_sigma_rad, std::sqrt(r + r * r), 0.02);
  EXPECT_EQ(a.roll_pitch_yaw_rad.z(), 0.0);
  // Levelling still works: the error-free window gives the true roll and pitch.
  EXPECT_NEAR(a.roll_pitch_yaw_rad.x(), rpy.x(), 1e-9);
  EXPECT_NEAR(a.roll_pitch_yaw_rad.y(), rpy.y(), 1e-9);
  EXPECT_NEAR(a.level_sigma_rad, 5e-3 * units::kStandardGravity / g, 1e-6);
}

TEST(StaticAlignment, NoHeadingAtThePoleOrFromAnEmptyWindow) {
  const double g = earth::normalGravity(kLatitude_rad, 0.0);
  const core::StaticWindow w =
      atRest(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  EXPECT_EQ(core::alignStatic(w, M_PI / 2, g, navigationGrade(), 1.0).heading_limit,
            core::HeadingLimit::kNearPole);
  const core::CoarseAlignment empty =
      core::alignStatic(core::StaticWindow{}, kLatitude_rad, g, navigationGrade(), 1.0);
  EXPECT_EQ(empty.heading_limit, core::HeadingLimit::kNoData);
  EXPECT_TRUE(std::isinf(empty.level_sigma_rad));
}

// ---------------------------------------------------------------------------------------------
// InitialAligner: the source chosen from what arrives, and the state it starts from.

namespace {

constexpr double kLatitudeAligner_rad = 36.5 * units::kDeg;
const earth::Geodetic kSite{kLatitudeAligner_rad, 127.5 * units::kDeg, 1000.0};

/// Six satellites 22 000 km away in fixed directions from the receiver, exact ranges and rates.
std::vector<core::SatelliteObservation> satellitesSeenFrom(const earth::Geodetic& rx,
                                                           const Eigen::Vector3d& vel_ned_mps,
                                                           double clock_m, double drift_mps) {
  const Eigen::Matrix3d C_n_e = earth::C_n_e(rx.latitude_rad, rx.longitude_rad);
  const Eigen::Vector3d rx_ecef = earth::geodeticToEcef(rx);
  const Eigen::Vector3d rx_vel_ecef = C_n_e * vel_ned_mps;
  const double az_el_deg[6][2] = {{0, 60}, {70, 30}, {140, 45}, {210, 20}, {280, 50}, {330, 15}};
  std::vector<core::SatelliteObservation> sats;
  for (int i = 0; i < 6; ++i) {
    const double az = az_el_deg[i][0] * units::kDeg;
    const double el = az_el_deg[i][1] * units::kDeg;
    const Eigen::Vector3d los_n(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                -std::sin(el));
    core::SatelliteObservation s;
    s.sv_id = i + 1;
    s.sat_pos_ecef_m = rx_ecef + C_n_e * los_n * 2.2e7;
    s.sat_vel_ecef_mps = C_n_e * los_n.cross(Eigen::Vector3d::UnitZ()).normalized() * 3000.0;
    const Eigen::Vector3d los_e = (s.sat_pos_ecef_m - rx_ecef).normalized();
    s.pseudorange_m = (s.sat_pos_ecef_m - rx_ecef).norm() + clock_m;
    s.pseudorange_rate_mps = los_e.dot(s.sat_vel_ecef_mps - rx_vel_ecef) + drift_mps;
    s.pseudorange_sigma_m = 3.0;
    s.pseudorange_rate_sigma_mps = 0.1;
    sats.push_back(s);
  }
  return sats;
}

/// One error-free increment ending at t_ns of a body with attitude C_b_n (at the site), specific
/// force f_n and, on top of the Earth rate, a body rate w_nb_b.
core::ImuIncrement incrementAt(std::int64_t t_ns, const Eigen::Matrix3d& C_b_n,
                               const Eigen::Vector3d& f_n_mps2,
                               const Eigen::Vector3d& w_nb_b_radps = Eigen::Vector3d::Zero()) {
  core::ImuIncrement inc;
  inc.time_ns = t_ns;
  inc.interval_s = kDt_s;
  inc.delta_vel_b_mps = C_b_n.transpose() * f_n_mps2 * kDt_s;
  inc.delta_angle_b_rad =
      (C_b_n.transpose() * earth::omegaIeNed(kSite.latitude_rad) + w_nb_b_radps) * kDt_s;
  return inc;
}

Eigen::Vector3d restForce_n() {
  return Eigen::Vector3d(0, 0, -earth::normalGravity(kSite.latitude_rad, kSite.height_m));
}

double levellingSigmaOf(const core::AlignmentErrorBudget& budget, double duration_s) {
  return core::levellingSigma(budget, duration_s,
                              earth::normalGravity(kSite.latitude_rad, kSite.height_m));
}

double attitudeError(const Eigen::Quaterniond& a, const Eigen::Matrix3d& truth) {
  return Eigen::AngleAxisd(a.toRotationMatrix() * truth.transpose()).angle();
}

}  // namespace

TEST(InitialAligner, GyrocompassesAtRestWithPositionAndClockFromPseudoranges) {
  core::InitialAlignmentConfig config;
  config.budget = navigationGrade();
  config.static_window_s = 60.0;
  core::InitialAligner aligner(config);
  const Eigen::Matrix3d C_b_n = core::dcmFromEuler(Eigen::Vector3d(1, -2, 123) * units::kDeg);
  constexpr double kClock_m = 3000.0;
  constexpr double kDrift_mps = 1.0;
  std::int64_t aligned_at_ns = -1;
  for (int i = 1; i <= 7000 && !aligner.aligned(); ++i) {
    const std::int64_t t_ns = i * 10'000'000LL;
    aligner.addImu(incrementAt(t_ns, C_b_n, restForce_n()));
    if (i == 50) {
      EXPECT_EQ(aligner.phase(), core::AlignmentPhase::kWaitingForPosition);
    }
    if (i % 100 == 0) {
      const double t_s = 1e-9 * static_cast<double>(t_ns);
      aligner.addPseudoranges(t_ns, satellitesSeenFrom(kSite, Eigen::Vector3d::Zero(),
                                                       kClock_m + kDrift_mps * t_s, kDrift_mps));
      if (i == 100) {
        EXPECT_EQ(aligner.phase(), core::AlignmentPhase::kWaitingForRest);
      }
    }
    if (aligner.aligned()) aligned_at_ns = t_ns;
  }
  ASSERT_TRUE(aligner.aligned());
  const core::AlignedStart& s = aligner.start();
  // A 60 s window once the detector's first second and one block of margin have passed.
  EXPECT_NEAR(1e-9 * static_cast<double>(aligned_at_ns), 62.0, 1.0);
  EXPECT_EQ(s.state.time_ns, aligned_at_ns);
  EXPECT_EQ(s.attitude_source, core::AttitudeSource::kGyrocompass);
  EXPECT_EQ(s.position_source, core::PositionSource::kPseudoranges);
  EXPECT_LT(attitudeError(s.state.q_b_to_n, C_b_n), 1e-7);
  EXPECT_LT(earth::differenceNed(s.state.position, kSite).norm(), 1e-3);
  EXPECT_LT(s.state.vel_ned_mps.norm(), 1e-6);
  ASSERT_TRUE(s.has_clock);
  const double t_s = 1e-9 * static_cast<double>(aligned_at_ns);
  EXPECT_NEAR(s.clock_bias_m, kClock_m + kDrift_mps * t_s, 1e-3);
  EXPECT_NEAR(s.clock_drift_mps, kDrift_mps, 1e-6);
  // The sigmas are the budget's: level and heading from static_alignment (here 60 s), position
  // from the DOP and the 3 m pseudorange sigma.
  EXPECT_NEAR(s.att_sigma_ned_rad.x(), levellingSigmaOf(config.budget, 60.0), 1e-9);
  EXPECT_DOUBLE_EQ(s.att_sigma_ned_rad.z(), s.gyrocompass_heading_sigma_rad);
  EXPECT_LT(s.att_sigma_ned_rad.z(), 0.2 * units::kDeg);
  EXPECT_GT(s.pos_sigma_ned_m.minCoeff(), 3.0);
  EXPECT_LT(s.pos_sigma_ned_m.maxCoeff(), 30.0);
}

TEST(InitialAligner, MemsLevelsAtRestThenTakesTheHeadingFromTheGnssCourse) {
  core::InitialAlignmentConfig config;
  config.budget.accel_bias_sigma_mps2 = 5 * units::kMilliG;
  config.budget.gyro_bias_sigma_radps = 10 * units::kDegPerHour;
  config.static_window_s = 20.0;
  config.course_min_speed_mps = 5.0;
  core::InitialAligner aligner(config);
  // 30 s at rest heading 70 deg, a 30 deg turn on the spot in 3 s, then 2 m/s^2 straight ahead.
  double yaw_deg = 70.0;
  double speed_mps = 0.0;
  earth::Geodetic position = kSite;
  for (int i = 1; i <= 4000 && !aligner.aligned(); ++i) {
    const std::int64_t t_ns = i * 10'000'000LL;
    const double t_s = 1e-9 * static_cast<double>(t_ns);
    Eigen::Vector3d w_nb_b = Eigen::Vector3d::Zero();
    double accel_mps2 = 0.0;
    if (t_s > 30.0 && t_s <= 33.0) w_nb_b.z() = 10.0 * units::kDeg;
    if (t_s > 33.0) accel_mps2 = 2.0;
    yaw_deg += w_nb_b.z() / units::kDeg * kDt_s;
    const Eigen::Matrix3d C_b_n = core::dcmFromEuler(Eigen::Vector3d(0, 0, yaw_deg) * units::kDeg);
    const Eigen::Vector3d forward_n = C_b_n.col(0);
    aligner.addImu(incrementAt(t_ns, C_b_n, restForce_n() + forward_n * accel_mps2, w_nb_b));
    speed_mps += accel_mps2 * kDt_s;
    position = earth::offsetNed(position, forward_n * speed_mps * kDt_s);
    if (i % 10 == 0) {  // 10 Hz fixes
      core::GnssFixMeasurement fix;
      fix.time_ns = t_ns;
      fix.position = position;
      fix.vel_ned_mps = forward_n * speed_mps;
      fix.pos_sigma_ned_m = Eigen::Vector3d::Constant(2.0);
      fix.vel_sigma_ned_mps = Eigen::Vector3d::Constant(0.1);
      aligner.addGnssFix(fix);
    }
    if (t_s > 22.5 && t_s < 33.0) {
      ASSERT_EQ(aligner.phase(), core::AlignmentPhase::kWaitingForCourse) << "at " << t_s << " s";
    }
    if (aligner.aligned()) {
      const core::AlignedStart& s = aligner.start();
      EXPECT_NEAR(t_s, 33.0 + 2.5, 0.11);  // the first fix at 5 m/s
      EXPECT_EQ(s.attitude_source, core::AttitudeSource::kGnssCourse);
      EXPECT_EQ(s.position_source, core::PositionSource::kGnssFix);
      // The heading is the course; the tilt is off by the horizontal Earth rate left out since
      // the last levelling at rest (the turn on the spot has no scatter, but windows shorter
      // than min_static_window_s do not level again): about 5.5 s, 3.3e-4 rad, which the tilt
      // sigma covers.
      EXPECT_NEAR(core::eulerFromDcm(s.state.q_b_to_n.toRotationMatrix()).z(),
                  yaw_deg * units::kDeg, 1e-9);
      const double error_rad = attitudeError(s.state.q_b_to_n, C_b_n);
      EXPECT_LT(error_rad, 4e-4);
      EXPECT_GT(s.att_sigma_ned_rad.x(), error_rad);
      EXPECT_GT(s.gyrocompass_heading_sigma_rad, 0.5);  // the MEMS gyro cannot gyrocompass
      EXPECT_NEAR(s.att_sigma_ned_rad.z(), std::hypot(config.course_sigma_rad, 0.1 / 5.0), 1e-3);
      EXPECT_FALSE(s.has_clock);
    }
  }
  EXPECT_TRUE(aligner.aligned());
}

TEST(InitialAligner, StarTrackerGivesTheAttitudeAtTheFirstSampleAfterTheFirstFix) {
  core::InitialAligner aligner(core::InitialAlignmentConfig{});
  const Eigen::Matrix3d C_b_n = core::dcmFromEuler(Eigen::Vector3d(20, -35, 250) * units::kDeg);
  const std::int64_t t_ns = 1'400'000'000'000'000'000LL;
  core::StarAttitudeMeasurement st;
  st.time_ns = t_ns;
  st.q_b_to_i = Eigen::Quaterniond(earth::C_i_e(1e-9 * static_cast<double>(t_ns)).transpose() *
                                   earth::C_n_e(kSite.latitude_rad, kSite.longitude_rad) * C_b_n);
  st.sigma_b_rad = Eigen::Vector3d(5, 5, 40) * units::kArcsec;
  aligner.addImu(incrementAt(t_ns, C_b_n, restForce_n()));
  aligner.addStarAttitude(st);  // no position yet: waits
  EXPECT_FALSE(aligner.aligned());
  core::GnssFixMeasurement fix;
  fix.time_ns = t_ns;
  fix.position = kSite;
  fix.vel_ned_mps = Eigen::Vector3d(7000, 500, 0);
  aligner.addGnssFix(fix);
  aligner.addStarAttitude(st);
  ASSERT_TRUE(aligner.aligned());
  const core::AlignedStart& s = aligner.start();
  EXPECT_EQ(s.attitude_source, core::AttitudeSource::kStarTracker);
  EXPECT_LT(attitudeError(s.state.q_b_to_n, C_b_n), 1e-9);
  EXPECT_LT((s.state.vel_ned_mps - fix.vel_ned_mps).norm(), 1e-9);
  // The body sigmas seen about NED: between the smallest and the largest body sigma.
  EXPECT_GE(s.att_sigma_ned_rad.minCoeff(), 5 * units::kArcsec - 1e-12);
  EXPECT_LE(s.att_sigma_ned_rad.maxCoeff(), 40 * units::kArcsec + 1e-12);
}
