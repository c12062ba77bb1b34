// Static coarse alignment: exact recovery of the attitude from error-free increments, the error
// budget against injected sensor errors, and the gyro grades that cannot gyrocompass.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "navbus/core/earth.hpp"
#include "navbus/core/rotation.hpp"
#include "navbus/core/static_alignment.hpp"
#include "navbus/core/units.hpp"

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
  const double heading = std::hypot(std::sqrt(bg * bg + arw * arw / T) / horizontal_rate,
                                    level * std::tan(kLatitude_rad));
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
  // 10 deg/h against 15.04 cos 45 deg/h of horizontal Earth rate: about 0.94 rad.
  EXPECT_NEAR(a.heading_sigma_rad, 10.0 / (15.041 * std::cos(kLatitude_rad)), 0.02);
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
