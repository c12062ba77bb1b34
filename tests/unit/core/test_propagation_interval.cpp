// The covariance propagated over several increments at once (propagation_interval.hpp,
// FilterTuning::covariance_period_s) against the increments' own transitions: one increment
// bit for bit, a tenth of a second of a tight turn within the interval's second-order terms,
// and a filter fusing fixes with either propagation.
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "navbus/core/filter/integrated_filter.hpp"
#include "navbus/core/filter/propagation_interval.hpp"
#include "navbus/core/ins/ins_error_model.hpp"
#include "navbus/sim/trajectory.hpp"

namespace core = navbus::core;
namespace earth = navbus::core::earth;
namespace layout = navbus::core::layout;

namespace {

/// A car at 20 m/s turning at 30 deg/s (10.5 m/s^2 across the track), its body yawing with it.
navbus::sim::VehicleTrajectory tightTurn() {
  navbus::sim::VehicleStart start;
  start.speed_mps = 20.0;
  std::vector<navbus::sim::Segment> segs(1);
  segs[0].duration_s = 120.0;
  segs[0].heading_rate_radps = segs[0].yaw_rate_radps = 30.0 * navbus::units::kDeg;
  return navbus::sim::VehicleTrajectory(start, segs, earth::GravityModel::kWgs84Normal);
}

struct Step {
  core::NavState state;  ///< at the increment's start
  Eigen::Vector3d f_b, w_ib_b;
  double dt;
};

std::vector<Step> steps(navbus::sim::VehicleTrajectory& traj, int n, double dt) {
  std::vector<Step> out;
  for (int k = 0; k < n; ++k) {
    const core::NavState s = traj.state();
    const auto inc = traj.advance(dt);
    out.push_back({s, inc.delta_vel_b_mps / dt, inc.delta_angle_b_rad / dt, dt});
  }
  return out;
}

core::ErrorDynamicsBlocks blocksOf(const Step& s) {
  return core::errorDynamicsBlocks(
      s.state, s.f_b, s.w_ib_b,
      earth::localEarth(earth::GravityModel::kWgs84Normal, s.state.position, s.state.vel_ned_mps));
}

}  // namespace

TEST(PropagationInterval, OneIncrementIsThatIncrementsOwnTransition) {
  auto traj = tightTurn();
  const Step s = steps(traj, 1, 0.005)[0];
  core::StateVector q = core::StateVector::LinSpaced(1e-9, 1e-6);
  core::PropagationInterval interval;
  interval.add(blocksOf(s), s.dt, q);
  const core::StateMatrix own = core::transitionMatrix(
      core::errorDynamics(s.state, s.f_b, s.w_ib_b, earth::GravityModel::kWgs84Normal), s.dt);
  EXPECT_TRUE(interval.transition() == own);  // bit for bit: covariance_period_s 0 as before
  EXPECT_TRUE(interval.processNoise() == q);
  EXPECT_EQ(interval.increments(), 1);
}

TEST(PropagationInterval, ATightTurnsTenthOfASecondMatchesTheProductOfItsIncrements) {
  // Given 20 increments of 5 ms through a 30 deg/s turn and a covariance with the tuning's
  // initial sigmas of a navigation-grade filter's 15 inertial states,
  auto traj = tightTurn();
  traj.advance(1.0);
  const std::vector<Step> s = steps(traj, 20, 0.005);
  core::FilterTuning t;
  const core::StateVector sigma = core::IntegratedFilter::initialSigma(t);
  core::StateMatrix P0 = core::StateMatrix::Zero();
  for (int i = 0; i < layout::kGyroBias.end(); ++i) P0(i, i) = sigma[i] * sigma[i];
  core::StateMatrix product = core::StateMatrix::Identity();
  core::PropagationInterval interval;
  for (const Step& k : s) {
    product = core::transitionMatrix(core::errorDynamics(blocksOf(k)), k.dt) * product;
    interval.add(blocksOf(k), k.dt, core::StateVector::Zero());
  }
  // when the interval propagates it in one step,
  const core::StateMatrix Phi = interval.transition();
  const core::StateMatrix P_steps = product * P0 * product.transpose();
  const core::StateMatrix P_interval = Phi * P0 * Phi.transpose();
  // then every element agrees with the increments' own product to 1e-6 of the elements' scale
  // sqrt(P_ii P_jj) (the second-order terms of F's change in the turn).
  double worst = 0.0;
  for (int i = 0; i < layout::kGyroBias.end(); ++i) {
    for (int j = 0; j < layout::kGyroBias.end(); ++j) {
      const double scale = std::sqrt(P_steps(i, i) * P_steps(j, j));
      worst = std::max(worst, std::abs(P_interval(i, j) - P_steps(i, j)) / scale);
    }
  }
  std::printf("largest difference of P over 0.1 s of the turn: %.2e of sqrt(P_ii P_jj)\n", worst);
  EXPECT_LT(worst, 1e-6);
  EXPECT_NEAR(interval.duration_s(), 0.1, 1e-12);
}

TEST(PropagationInterval, AFilterWithTheCovarianceEveryTenthOfASecondAgreesWithOneEveryIncrement) {
  // Given two filters on the turn's perfect increments at 200 Hz, one propagating its
  // covariance every increment and one every 0.1 s, both fusing the truth's position and
  // velocity each second from the same wrong start,
  auto traj = tightTurn();
  core::FilterTuning every;
  every.gate_sigma = 0.0;
  core::FilterTuning lazy = every;
  lazy.covariance_period_s = 0.1;
  const core::StateMask mask = core::maskOf(
      {layout::kPos, layout::kVel, layout::kAtt, layout::kAccelBias, layout::kGyroBias});
  core::NavState start = traj.state();
  start.time_ns = 0;
  start.position = earth::offsetNed(start.position, Eigen::Vector3d(3.0, -2.0, 1.0));
  start.vel_ned_mps += Eigen::Vector3d(0.2, -0.1, 0.05);
  core::IntegratedFilter a, b;
  a.initialize(start, 0.0, 0.0, every, mask);
  b.initialize(start, 0.0, 0.0, lazy, mask);
  const double dt = 0.005;
  double worst_sigma = 0.0, worst_position_m = 0.0;
  bool pending_seen = false;
  for (int k = 1; k <= 200 * 60; ++k) {
    const auto inc = traj.advance(dt);
    const core::ImuIncrement m{static_cast<std::int64_t>(std::llround(k * dt * 1e9)), dt,
                               inc.delta_vel_b_mps, inc.delta_angle_b_rad};
    a.propagate(m);
    b.propagate(m);
    EXPECT_FALSE(a.covariancePending());
    pending_seen = pending_seen || b.covariancePending();
    if (k % 200 != 0) continue;
    // (the update settles the pending propagation first)
    const core::NavState truth = traj.state();
    for (core::IntegratedFilter* f : {&a, &b}) {
      f->update(core::positionMeasurement(f->state(), truth.position, Eigen::Vector3d::Ones()),
                core::AidingKind::kPosition);
      f->update(
          core::velocityMeasurement(f->state(), truth.vel_ned_mps, Eigen::Vector3d::Constant(0.05)),
          core::AidingKind::kVelocity);
    }
    EXPECT_FALSE(b.covariancePending());
    for (int i = 0; i < layout::kGyroBias.end(); ++i) {
      const double sa = std::sqrt(a.covariance()(i, i)), sb = std::sqrt(b.covariance()(i, i));
      worst_sigma = std::max(worst_sigma, std::abs(sb - sa) / sa);
    }
    worst_position_m = std::max(
        worst_position_m, earth::differenceNed(a.state().position, b.state().position).norm());
  }
  // then the lazy filter did wait, and its sigmas and solution are the other's: within 1e-4
  // of each sigma and 1 mm.
  std::printf("60 s of the turn: sigmas within %.2e, positions within %.2e m\n", worst_sigma,
              worst_position_m);
  EXPECT_TRUE(pending_seen);
  EXPECT_LT(worst_sigma, 1e-4);
  EXPECT_LT(worst_position_m, 1e-3);
}
