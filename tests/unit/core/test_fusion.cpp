// The fusion structures, the measurement types of seeds 001 and 004 and the multi-dimensional
// stage logic, each checked on a constructed case (given / when / then).
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "navbus/core/engine/navigation_engine.hpp"
#include "navbus/core/filter/information_fusion.hpp"
#include "navbus/core/filter/integrated_filter.hpp"
#include "navbus/core/filter/multi_dimensional.hpp"
#include "navbus/core/ins/static_alignment.hpp"
#include "navbus/core/math/rotation.hpp"

namespace core = navbus::core;
namespace earth = navbus::core::earth;
namespace layout = navbus::core::layout;

namespace {

core::NavState movingTruth(const Eigen::Vector3d& rpy, const Eigen::Vector3d& vel) {
  core::NavState t;
  t.time_ns = 1'400'000'000'000'000'000;
  t.position = {36.4 * M_PI / 180, 127.4 * M_PI / 180, 80.0};
  t.vel_ned_mps = vel;
  t.q_b_to_n = Eigen::Quaterniond(core::dcmFromEuler(rpy));
  return t;
}

/// The INS state with the error dx (estimate minus truth) applied to the truth.
core::NavState withError(const core::NavState& truth, const core::StateVector& dx) {
  core::NavState s = truth;
  s.position = earth::offsetNed(truth.position, dx.segment<3>(layout::kPos.index));
  s.vel_ned_mps += dx.segment<3>(layout::kVel.index);
  s.q_b_to_n =
      core::quaternionFromRotationVector(-dx.segment<3>(layout::kAtt.index)) * truth.q_b_to_n;
  return s;
}

core::FilterTuning tuning() {
  core::FilterTuning t;
  t.pos_sigma_m = 10;
  t.vel_sigma_mps = 1;
  t.level_sigma_rad = t.heading_sigma_rad = 0.02;
  t.gate_sigma = 0;
  return t;
}

const core::StateMask kFifteen =
    core::maskOf({layout::kPos, layout::kVel, layout::kAtt, layout::kAccelBias, layout::kGyroBias});

double attitudeError(const core::NavState& e, const core::NavState& t) {
  return Eigen::AngleAxisd(e.q_b_to_n * t.q_b_to_n.conjugate()).angle();
}

}  // namespace

TEST(AidingMeasurements, NonHolonomicAndZeroVelocityInnovationsEqualHTimesTheError) {
  // Given a vehicle driving along its body x axis with a velocity and attitude error,
  const core::NavState truth = movingTruth(
      {0.05, -0.03, 0.8}, core::dcmFromEuler({0.05, -0.03, 0.8}) * Eigen::Vector3d(12.0, 0.0, 0.0));
  core::StateVector dx = core::StateVector::Zero();
  dx.segment<3>(layout::kVel.index) << 0.05, -0.04, 0.02;
  dx.segment<3>(layout::kAtt.index) << 2e-3, -1e-3, 3e-3;
  const core::NavState ins = withError(truth, dx);
  // when the constraints are predicted from the erroneous state, then z = H dx to first order.
  const auto nhc = core::nonHolonomicMeasurement(ins, 0.1);
  EXPECT_LT((nhc.z - nhc.h * dx).norm(), 1e-3 * nhc.z.norm() + 1e-4);
  EXPECT_GT(nhc.z.norm(), 0.02);  // the constructed error is visible
  const auto zupt = core::zeroVelocityMeasurement(
      withError(movingTruth(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()), dx), 0.01);
  EXPECT_LT((zupt.z - zupt.h * dx).norm(), 1e-12);
}

TEST(AidingMeasurements, TheConstraintExpectsTheVelocityPitchedAsConfigured) {
  // Given a car whose velocity lies 0.4 deg below its body's forward axis (its nose up as it
  // speeds up), seen without error and with a velocity and attitude error,
  const double pitch_v = -0.4 * M_PI / 180;
  const Eigen::Vector3d rpy(0.02, 0.03, -1.1);
  const Eigen::Vector3d v_b(12.0 * std::cos(pitch_v), 0.0, -12.0 * std::sin(pitch_v));
  const core::NavState truth = movingTruth(rpy, core::dcmFromEuler(rpy) * v_b);
  // when the constraint expects that pitch, then the true state meets it exactly,
  const auto exact = core::nonHolonomicMeasurement(truth, 0.1, pitch_v);
  EXPECT_LT(exact.z.norm(), 1e-12);
  EXPECT_GT(std::abs(core::nonHolonomicMeasurement(truth, 0.1).z[1]), 0.08);  // a rigid body's
  // and the erroneous state's innovation is H dx to first order.
  core::StateVector dx = core::StateVector::Zero();
  dx.segment<3>(layout::kVel.index) << 0.05, -0.04, 0.02;
  dx.segment<3>(layout::kAtt.index) << 2e-3, -1e-3, 3e-3;
  const auto nhc = core::nonHolonomicMeasurement(withError(truth, dx), 0.1, pitch_v);
  EXPECT_LT((nhc.z - nhc.h * dx).norm(), 1e-3 * nhc.z.norm() + 1e-4);
  EXPECT_GT(nhc.z.norm(), 0.02);
}

TEST(AidingMeasurements, TheConstraintHoldsInTheVehiclesAxesWithTheMountingStates) {
  // Given a car driving along its own forward axis, whose body axes (the IMU's, rotated by the
  // published mounting) are off the vehicle's by a small mounting misalignment mu,
  const Eigen::Vector3d mu_true(1e-3, 0.01, -0.015);
  const Eigen::Matrix3d C_b_v = Eigen::Matrix3d::Identity() - core::skew(mu_true);
  const Eigen::Vector3d v_b = C_b_v.inverse() * Eigen::Vector3d(12.0, 0.0, 0.0);
  const Eigen::Vector3d rpy(0.02, -0.01, 0.7);
  const core::NavState truth = movingTruth(rpy, core::dcmFromEuler(rpy) * v_b);
  // when the constraint is predicted with the true mounting, it holds exactly; without the
  // mounting states the misalignment shows as a lateral velocity of v mu_z,
  const auto exact = core::nonHolonomicMeasurement(truth, 0.1, 0.0, &mu_true);
  EXPECT_LT(exact.z.norm(), 1e-12);
  EXPECT_NEAR(core::nonHolonomicMeasurement(truth, 0.1).z[0], 12.0 * mu_true.z(), 2e-3);
  // and with errors in the velocity, the attitude and the mounting estimate (estimate minus
  // truth), z = H dx to first order; each mounting column is the finite difference.
  core::StateVector dx = core::StateVector::Zero();
  dx.segment<3>(layout::kVel.index) << 0.05, -0.04, 0.02;
  dx.segment<3>(layout::kAtt.index) << 2e-3, -1e-3, 3e-3;
  dx.segment<3>(layout::kMountingMisalignment.index) << 1e-3, -2e-3, 3e-3;
  const Eigen::Vector3d mu_est = mu_true + dx.segment<3>(layout::kMountingMisalignment.index);
  const core::NavState ins = withError(truth, dx);
  const auto nhc = core::nonHolonomicMeasurement(ins, 0.1, 0.0, &mu_est);
  EXPECT_LT((nhc.z - nhc.h * dx).norm(), 1e-3 * nhc.z.norm() + 1e-4);
  EXPECT_GT(nhc.z.norm(), 0.02);
  const double eps = 1e-6;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d mu_plus = mu_est;
    mu_plus[i] += eps;
    const auto plus = core::nonHolonomicMeasurement(ins, 0.1, 0.0, &mu_plus);
    const Eigen::Vector2d column = (plus.z - nhc.z) / eps;
    EXPECT_LT((column - nhc.h.col(layout::kMountingMisalignment.index + i)).norm(), 1e-6)
        << "mounting column " << i;
  }
  // The yaw and pitch columns are -v and +v along the (computed) forward axis.
  const Eigen::Vector3d v_b_ins = ins.q_b_to_n.conjugate() * ins.vel_ned_mps;
  EXPECT_NEAR(nhc.h(0, layout::kMountingMisalignment.index + 2), -v_b_ins.x(), 1e-9);
  EXPECT_NEAR(nhc.h(1, layout::kMountingMisalignment.index + 1), v_b_ins.x(), 1e-9);
}

TEST(IntegratedFilter, EveryUpdateTypeReducesAConstructedError) {
  const Eigen::Vector3d rpy(0.1, -0.05, 2.0);
  const core::NavState truth =
      movingTruth(rpy, core::dcmFromEuler(rpy) * Eigen::Vector3d(15, 0, 0));
  core::StateVector dx = core::StateVector::Zero();
  dx.segment<3>(layout::kPos.index) << 8.0, -6.0, 4.0;
  dx.segment<3>(layout::kVel.index) << 0.6, -0.5, 0.3;
  dx.segment<3>(layout::kAtt.index) << 0.01, -0.012, 0.015;
  struct Case {
    const char* name;
    std::function<void(core::IntegratedFilter&)> update;
    std::function<double(const core::NavState&)> error;
  };
  const std::vector<Case> cases = {
      {"position",
       [&](core::IntegratedFilter& f) {
         f.update(core::positionMeasurement(f.state(), truth.position, Eigen::Vector3d::Ones()),
                  core::AidingKind::kPosition);
       },
       [&](const core::NavState& s) {
         return earth::differenceNed(s.position, truth.position).norm();
       }},
      {"velocity",
       [&](core::IntegratedFilter& f) {
         f.update(core::velocityMeasurement(f.state(), truth.vel_ned_mps,
                                            Eigen::Vector3d::Constant(0.05)),
                  core::AidingKind::kVelocity);
       },
       [&](const core::NavState& s) { return (s.vel_ned_mps - truth.vel_ned_mps).norm(); }},
      {"star tracker attitude",
       [&](core::IntegratedFilter& f) {
         const double t_s = 1e-9 * static_cast<double>(truth.time_ns);
         const Eigen::Quaterniond q_b_i(
             earth::C_i_e(t_s).transpose() *
             earth::C_n_e(truth.position.latitude_rad, truth.position.longitude_rad) *
             truth.q_b_to_n.toRotationMatrix());
         f.update(core::attitudeMeasurement(f.state(), q_b_i, Eigen::Vector3d::Constant(1e-4),
                                            Eigen::Vector3d::Zero()),
                  core::AidingKind::kAttitude);
       },
       [&](const core::NavState& s) { return attitudeError(s, truth); }},
      {"zero velocity",
       [&](core::IntegratedFilter& f) {
         f.update(core::zeroVelocityMeasurement(f.state(), 0.01), core::AidingKind::kZeroVelocity);
       },
       [&](const core::NavState& s) { return s.vel_ned_mps.norm(); }},
      {"non-holonomic",
       [&](core::IntegratedFilter& f) {
         f.update(core::nonHolonomicMeasurement(f.state(), 0.05), core::AidingKind::kNonHolonomic);
       },
       [&](const core::NavState& s) {
         return (s.q_b_to_n.conjugate() * s.vel_ned_mps).tail<2>().norm();
       }},
  };
  for (const Case& c : cases) {
    // Given an INS with a known error and a filter whose prior covers it,
    core::NavState start = withError(truth, dx);
    if (std::string(c.name) == "zero velocity")
      start.vel_ned_mps = dx.segment<3>(layout::kVel.index);
    core::IntegratedFilter f;
    f.initialize(start, 0, 0, tuning(), kFifteen);
    const double before = c.error(f.state());
    // when one update of this type is applied,
    c.update(f);
    // then the error it observes shrinks, and P stays symmetric positive definite.
    const double after = c.error(f.state());
    std::printf("%-22s error %.4g -> %.4g\n", c.name, before, after);
    EXPECT_LT(after, 0.5 * before) << c.name;
    const core::StateMatrix& P = f.covariance();
    EXPECT_LT((P - P.transpose()).norm(), 1e-12 * P.norm()) << c.name;
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<core::StateMatrix>(P).eigenvalues().minCoeff(), 0.0);
  }
}

TEST(IntegratedFilter, CovarianceStaysSymmetricPositiveDefiniteAcrossAttitudes) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d rpy(angle(rng) / 2, angle(rng) / 4, angle(rng));
    core::NavState s = movingTruth(rpy, Eigen::Vector3d(angle(rng), angle(rng), 0.1 * angle(rng)));
    core::IntegratedFilter f;
    f.initialize(s, 0, 0, tuning(), ~core::StateMask(), core::FusionStructure::kCentralized);
    core::ImuIncrement inc;
    inc.interval_s = 0.01;
    inc.delta_vel_b_mps =
        s.q_b_to_n.conjugate() * Eigen::Vector3d(0.3, -0.2, -9.80) * inc.interval_s;
    inc.delta_angle_b_rad = Eigen::Vector3d(0.01, -0.02, 0.05) * inc.interval_s;
    for (int k = 1; k <= 300; ++k) {
      inc.time_ns = s.time_ns + std::int64_t{k} * 10'000'000;
      f.propagate(inc);
      if (k % 50 == 0) {
        f.update(
            core::velocityMeasurement(f.state(), f.state().vel_ned_mps + Eigen::Vector3d(0.1, 0, 0),
                                      Eigen::Vector3d::Constant(0.05)),
            core::AidingKind::kVelocity);
      }
    }
    const core::StateMatrix& P = f.covariance();
    EXPECT_LT((P - P.transpose()).norm(), 1e-12 * P.norm());
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<core::StateMatrix>(P).eigenvalues().minCoeff(), 0.0)
        << "rpy " << rpy.transpose();
  }
}

TEST(IntegratedFilter, FederatedNoResetFusionEqualsCentralizedForIndependentSensors) {
  // Given the same INS error and two independent sensors (GNSS position, star tracker),
  const core::NavState truth = movingTruth({0.02, 0.01, 1.0}, {20, 5, 0});
  core::StateVector dx = core::StateVector::Zero();
  dx.segment<3>(layout::kPos.index) << 5.0, -4.0, 3.0;
  dx.segment<3>(layout::kAtt.index) << 2e-3, -1e-3, 4e-3;
  const double t_s = 1e-9 * static_cast<double>(truth.time_ns);
  const Eigen::Quaterniond q_b_i(
      earth::C_i_e(t_s).transpose() *
      earth::C_n_e(truth.position.latitude_rad, truth.position.longitude_rad) *
      truth.q_b_to_n.toRotationMatrix());
  auto run = [&](core::FusionStructure s) {
    core::IntegratedFilter f;
    f.initialize(withError(truth, dx), 0, 0, tuning(), kFifteen, s);
    f.update(core::positionMeasurement(f.state(), truth.position, Eigen::Vector3d::Ones()),
             core::AidingKind::kPosition);
    f.update(core::attitudeMeasurement(f.state(), q_b_i, Eigen::Vector3d::Constant(1e-4),
                                       Eigen::Vector3d::Zero()),
             core::AidingKind::kAttitude);
    return f;
  };
  // when the centralized filter takes both and the federated master fuses the two locals
  // (eqs. 28-29, information shared 1/2 each),
  const core::IntegratedFilter c = run(core::FusionStructure::kCentralized);
  const core::IntegratedFilter fed = run(core::FusionStructure::kFederated);
  // then estimate and covariance agree (exactly for linear models; here to the linearization).
  const auto P15c = c.covariance().topLeftCorner<15, 15>();
  const auto P15f = fed.covariance().topLeftCorner<15, 15>();
  EXPECT_LT((P15c - P15f).norm(), 1e-6 * P15c.norm());
  EXPECT_LT(earth::differenceNed(c.state().position, fed.state().position).norm(), 1e-3);
  EXPECT_LT(attitudeError(c.state(), fed.state()), 1e-7);
  // and the local filters keep their own (larger) covariances: no reset.
  EXPECT_GT(fed.local(1).P()(0, 0), 10.0 * fed.covariance()(0, 0));
}

TEST(InnovationWindow, EstimatesRFromTheInnovationsWithTheFloor) {
  core::InnovationWindow<3> w;
  w.configure(4, Eigen::Vector3d::Constant(0.5));
  const Eigen::Matrix3d hpht = Eigen::Vector3d(1.0, 1.0, 30.0).asDiagonal();
  for (double v : {3.0, -3.0, 3.0, -3.0}) w.push(Eigen::Vector3d(v, 2 * v, v));
  ASSERT_TRUE(w.full());
  const Eigen::Matrix3d R = w.adaptedR(hpht);
  EXPECT_DOUBLE_EQ(R(0, 0), 9.0 - 1.0);  // eq. 32: C - H P H^T
  EXPECT_DOUBLE_EQ(R(1, 1), 36.0 - 1.0);
  EXPECT_DOUBLE_EQ(R(2, 2), 0.25);  // eq. 33: at or below zero -> the floor xi
  EXPECT_DOUBLE_EQ(R(0, 1), 0.0);
  // A fault that ends leaves the window after N epochs.
  for (int i = 0; i < 4; ++i) w.push(Eigen::Vector3d::Constant(1.0));
  EXPECT_DOUBLE_EQ(w.adaptedR(hpht)(0, 0), 0.25);
}

TEST(MultiDimensionalFilter, StagesMasksAndResetsFollowFigure8) {
  EXPECT_EQ(core::stageMask(core::MdfStage::kF1ZeroVelocity).count(), 8u);
  EXPECT_EQ(core::stageMask(core::MdfStage::kF2Gnss).count(), 15u);
  EXPECT_EQ(core::stageMask(core::MdfStage::kF3Recovery).count(), 9u);
  EXPECT_EQ(core::stageMask(core::MdfStage::kF4Constraint).count(), 12u);
  core::MdfConfig cfg;
  cfg.recovery_s = 5.0;
  core::StageSelector sel;
  sel.configure(cfg);
  const std::int64_t s = 1'000'000'000;
  using R = core::CovarianceReset;
  using S = core::MdfStage;
  struct Step {
    bool stationary, gnss;
    double t;
    S stage;
    R reset;
  };
  const Step steps[] = {
      {true, true, 0, S::kF1ZeroVelocity, R::kNone},   // start, standing
      {false, true, 10, S::kF2Gnss, R::kFsA},          // drives off
      {false, false, 50, S::kF4Constraint, R::kFs},    // outage
      {false, true, 80, S::kF3Recovery, R::kFsI},      // GNSS back
      {false, true, 84, S::kF3Recovery, R::kNone},     // still recovering
      {false, true, 85, S::kF2Gnss, R::kFs},           // 5 s later
      {true, true, 95, S::kF1ZeroVelocity, R::kFs},    // stops
      {false, false, 105, S::kF4Constraint, R::kFsA},  // drives off in an outage
  };
  for (const Step& st : steps) {
    const core::StageDecision d =
        sel.update(st.stationary, st.gnss, static_cast<std::int64_t>(st.t * s));
    EXPECT_EQ(d.stage, st.stage) << "t " << st.t;
    EXPECT_EQ(d.reset, st.reset) << "t " << st.t;
  }
  // Case II resets everything when GNSS returns; case I never resets.
  for (auto [policy, expected] : {std::pair{core::MdfPolicy::kResetAll, R::kAll},
                                  std::pair{core::MdfPolicy::kContinue, R::kNone}}) {
    cfg.policy = policy;
    core::StageSelector b;
    b.configure(cfg);
    b.update(false, true, 0);
    b.update(false, false, 50 * s);
    EXPECT_EQ(b.update(false, true, 80 * s).reset, expected);
  }
}

TEST(NavigationEngine, RefusesStructuresThatDoNotApply) {
  core::EngineConfig c;
  c.aiding = core::AidingMode::kMultiDimensional;
  core::NavigationEngine mdf(c);
  EXPECT_FALSE(mdf.selectFusion(core::FusionStructure::kFederated));
  EXPECT_FALSE(mdf.selectFusion(core::FusionStructure::kAdaptive));
  EXPECT_TRUE(mdf.selectFusion(core::FusionStructure::kCentralized));
  c.aiding = core::AidingMode::kLooselyCoupled;
  c.use_star_tracker = true;
  core::NavigationEngine lc(c);
  EXPECT_TRUE(lc.selectFusion(core::FusionStructure::kFederated));
  EXPECT_TRUE(lc.selectFusion(core::FusionStructure::kAdaptive));
  c.aiding = core::AidingMode::kInertialOnly;
  core::NavigationEngine ins(c);
  EXPECT_FALSE(ins.selectFusion(core::FusionStructure::kCentralized));
}

TEST(NavigationEngine, RefusesIncrementsThatDoNotFollowTheStateTime) {
  // Given an engine that has integrated two increments,
  core::EngineConfig c;
  c.initial_state = movingTruth(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  core::NavigationEngine e(c);
  core::ImuIncrement inc;
  inc.interval_s = 0.01;
  inc.delta_vel_b_mps = Eigen::Vector3d(0, 0, -9.8 * 0.01);
  inc.time_ns = 1'000'000'000;
  e.addImu(inc);
  inc.time_ns += 10'000'000;
  e.addImu(inc);
  const core::NavState before = e.state();
  // when an increment repeats a time, goes back, or has a bad interval,
  inc.time_ns -= 10'000'000;
  e.addImu(inc);
  inc.time_ns -= 1'000'000'000;
  e.addImu(inc);
  inc.time_ns = 1'030'000'000;
  inc.interval_s = -0.01;
  e.addImu(inc);
  inc.interval_s = std::nan("");
  e.addImu(inc);
  // then none is integrated and each is counted.
  EXPECT_EQ(e.counters().imu_refused, 4u);
  EXPECT_EQ(e.counters().imu_used, 2u);
  EXPECT_EQ(e.state().time_ns, before.time_ns);
  EXPECT_EQ(e.state().vel_ned_mps, before.vel_ned_mps);
}

namespace {
/// A filter at rest at `truth` with the given heading and gyro-bias sigmas.
core::IntegratedFilter filterAtRest(const core::NavState& truth, double heading_sigma_rad,
                                    double gyro_bias_sigma_deg_per_h) {
  core::FilterTuning t = tuning();
  t.heading_sigma_rad = heading_sigma_rad;
  t.gyro_bias_sigma_radps = gyro_bias_sigma_deg_per_h * M_PI / 180 / 3600;
  core::IntegratedFilter f;
  f.initialize(truth, 0, 0, t, kFifteen);
  return f;
}
}  // namespace

TEST(IntegratedFilter, EarthRateRemainderFloorsTheComputedNorthGyroBiasVariance) {
  // Given a filter at rest with a gyrocompassing heading sigma of 83 mrad, heading 0.8 rad, and a
  // gyro-bias covariance that claims the computed-north channel known to 0.001 deg/h,
  const core::NavState truth = movingTruth({0.0, 0.0, 0.8}, Eigen::Vector3d::Zero());
  core::IntegratedFilter f = filterAtRest(truth, 0.083, 0.001);
  const Eigen::Vector3d north_b = truth.q_b_to_n.conjugate() * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d east_b = truth.q_b_to_n.conjugate() * Eigen::Vector3d::UnitY();
  const auto variance = [&](const Eigen::Vector3d& u) {
    return u.dot(f.covariance().block<3, 3>(layout::kGyroBias.index, layout::kGyroBias.index) * u);
  };
  const double east_before = variance(east_b);
  // when the floor is applied,
  f.floorEarthRateRemainderVariance();
  // then that channel's variance is the remainder's, Var(W cos L cos psi) for psi ~ N(0, s^2)
  // = (W cos L)^2 (1 - e^(-s^2))^2 / 2 (0.059 deg/h here), and the east channel is untouched;
  const double w_h = earth::kRotationRate_radps * std::cos(truth.position.latitude_rad);
  const double expected = 0.5 * std::pow(w_h * (1.0 - std::exp(-0.083 * 0.083)), 2);
  EXPECT_NEAR(variance(north_b), expected, 1e-9 * expected);
  EXPECT_NEAR(std::sqrt(expected) / (M_PI / 180 / 3600), 0.059, 0.001);
  EXPECT_NEAR(variance(east_b), east_before, 1e-12 * expected);
  // a covariance that already says more is left as it is.
  const core::StateMatrix P = f.covariance();
  f.floorEarthRateRemainderVariance();
  EXPECT_EQ(f.covariance(), P);
}

TEST(IntegratedFilter, GyrocompassHeadingFloorKeepsTheHeadingAndEastGyroBiasCombination) {
  // Given a filter at rest, heading 0.8 rad, that claims its heading to 20 mrad (gyro biases
  // 1 deg/h),
  const core::NavState truth = movingTruth({0.0, 0.0, 0.8}, Eigen::Vector3d::Zero());
  core::IntegratedFilter f = filterAtRest(truth, 0.020, 1.0);
  const double w_h = earth::kRotationRate_radps * std::cos(truth.position.latitude_rad);
  const Eigen::Vector3d east_b = truth.q_b_to_n.conjugate() * Eigen::Vector3d::UnitY();
  const auto variance = [&](const core::StateVector& u) { return u.dot(f.covariance() * u); };
  core::StateVector heading = core::StateVector::Zero();
  heading[layout::kAtt.index + 2] = 1.0;
  core::StateVector combination = heading * w_h;  // W cos L phi_D + e_g^n_E: what rest measures
  combination.segment<3>(layout::kGyroBias.index) = east_b;
  const double combination_before = variance(combination);
  // when the floor of an 83 mrad gyrocompass is applied,
  f.floorGyrocompassHeadingVariance(0.083);
  // then the heading's variance is the gyrocompass's, and the combination rest measures is as
  // well known as before (the variance went along the direction that keeps it);
  EXPECT_NEAR(variance(heading), 0.083 * 0.083, 1e-12);
  EXPECT_NEAR(variance(combination), combination_before, 1e-9 * combination_before);
  // a covariance that already says less is left as it is.
  const core::StateMatrix P = f.covariance();
  f.floorGyrocompassHeadingVariance(0.05);
  EXPECT_EQ(f.covariance(), P);
}

TEST(IntegratedFilter, AHeadingCorrectionTurnsTheLevelledTiltsWithTheComputedFrame) {
  // Given a filter levelled at rest, heading 0.8 rad: its tilts are the horizontal accelerometer
  // biases over g through the computed frame (static_alignment.cpp step 8), a combination the
  // covariance holds to 1 urad while each part is 1 mrad,
  const core::NavState truth = movingTruth({0.0, 0.0, 0.8}, Eigen::Vector3d::Zero());
  const core::FilterTuning t = tuning();
  const double g = earth::normalGravity(truth.position.latitude_rad, truth.position.height_m);
  const auto levelled = [&](const Eigen::Quaterniond& q) -> Eigen::Matrix<double, 2, 3> {
    return core::alignmentSensitivity(q.toRotationMatrix(), truth.position.latitude_rad, g, false)
        .d_att_d_accel_bias_b.topRows<2>();
  };
  const Eigen::Matrix<double, 2, 3> S = levelled(truth.q_b_to_n);
  const double var_a = t.accel_bias_sigma_mps2 * t.accel_bias_sigma_mps2;
  core::StateVector sigma = core::IntegratedFilter::initialSigma(t);
  core::StateMatrix P0 = sigma.array().square().matrix().asDiagonal();
  P0.block<2, 2>(layout::kAtt.index, layout::kAtt.index) =
      var_a * S * S.transpose() + 1e-12 * Eigen::Matrix2d::Identity();
  P0.block<2, 3>(layout::kAtt.index, layout::kAccelBias.index) = -var_a * S;
  P0.block<3, 2>(layout::kAccelBias.index, layout::kAtt.index) = -var_a * S.transpose();
  core::IntegratedFilter f;
  f.initialize(truth, 0, 0, t, kFifteen, core::FusionStructure::kCentralized, P0);
  // the tilts and the bias errors e = -b: phi_h + S e, in the frame the filter computes
  const auto combinationVariance = [&]() {
    Eigen::Matrix<double, 2, layout::kSize> u = Eigen::Matrix<double, 2, layout::kSize>::Zero();
    u.middleCols<2>(layout::kAtt.index).setIdentity();
    u.middleCols<3>(layout::kAccelBias.index) = levelled(f.state().q_b_to_n);
    return Eigen::Matrix2d(u * f.covariance() * u.transpose()).trace();
  };
  ASSERT_LT(combinationVariance(), 3e-12);
  // when a measured heading corrects it by 50 mrad (a normal update, not the course check),
  core::AidingMeasurement<1> m;
  m.h.setZero();
  m.h(0, layout::kAtt.index + 2) = 1.0;
  m.z << 0.05;
  m.r << 1e-8;
  f.update(m, core::AidingKind::kAttitude);
  const double yaw = core::eulerFromDcm(f.state().q_b_to_n.toRotationMatrix()).z();
  ASSERT_NEAR(std::abs(yaw - 0.8), 0.05, 1e-3);
  // then the combination in the new frame is still known to 1 urad: the tilts turned with the
  // frame. Left unturned they would be off by 50 mrad of each tilt (50 urad).
  EXPECT_LT(combinationVariance(), 3e-12);
}
