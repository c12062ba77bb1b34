// Issue 4 groundwork: the tightly coupled measurement model's Jacobians against numerical
// differences, the Joseph-form gated update, and the covariance propagation.
#include <bitset>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "navbus/core/filter/error_state.hpp"
#include "navbus/core/gnss/gnss_measurement.hpp"
#include "navbus/core/math/kalman_update.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/sparse_rows.hpp"
#include "navbus/sim/constellation.hpp"

namespace earth = navbus::core::earth;
namespace layout = navbus::core::layout;
using StateVec = Eigen::Matrix<double, layout::kSize, 1>;
using StateMat = Eigen::Matrix<double, layout::kSize, layout::kSize>;

namespace {
navbus::core::NavState ins() {
  navbus::core::NavState s;
  s.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 1000.0};
  s.vel_ned_mps = Eigen::Vector3d(200.0, 5.0, -1.0);
  return s;
}

/// Moves a state by a position error in NED metres and a velocity error.
navbus::core::NavState perturbed(navbus::core::NavState s, const Eigen::Vector3d& dpos_ned,
                                 const Eigen::Vector3d& dvel) {
  const earth::Radii r = earth::radiiOfCurvature(s.position.latitude_rad);
  s.position.latitude_rad += dpos_ned.x() / (r.meridian_m + s.position.height_m);
  s.position.longitude_rad += dpos_ned.y() / ((r.prime_vertical_m + s.position.height_m) *
                                              std::cos(s.position.latitude_rad));
  s.position.height_m -= dpos_ned.z();
  s.vel_ned_mps += dvel;
  return s;
}

std::vector<navbus::core::SatelliteObservation> satellites(const navbus::core::NavState& s) {
  navbus::sim::Constellation c(navbus::sim::ConstellationConfig{});
  const Eigen::Vector3d r = earth::geodeticToEcef(s.position);
  std::vector<navbus::core::SatelliteObservation> out;
  for (const auto& k : c.almanac()) {
    const auto st = c.state(k.sv_id, 1.4e9);
    if ((st.pos_ecef_m - r).normalized().dot(r.normalized()) > 0.1) {
      navbus::core::SatelliteObservation o;
      o.sv_id = k.sv_id;
      o.sat_pos_ecef_m = st.pos_ecef_m;
      o.sat_vel_ecef_mps = st.vel_ecef_mps;
      out.push_back(o);
    }
  }
  return out;
}
}  // namespace

TEST(TightlyCoupledModel, JacobiansMatchNumericalDifferences) {
  const auto s = ins();
  const auto sats = satellites(s);
  ASSERT_GE(sats.size(), 4u);
  for (const auto& sat : sats) {
    const auto p0 = navbus::core::predictRange(s, 100.0, 2.0, sat);
    for (int axis = 0; axis < 3; ++axis) {
      // Position: +1 m along each NED axis (the estimate moves, so the error grows by +1 m).
      StateVec dx = StateVec::Zero();
      dx[layout::kPos.index + axis] = 1.0;
      const auto pp = navbus::core::predictRange(
          perturbed(s, Eigen::Vector3d::Unit(axis), Eigen::Vector3d::Zero()), 100.0, 2.0, sat);
      EXPECT_NEAR(pp.pseudorange_m - p0.pseudorange_m, (p0.h_range * dx)(0, 0), 1e-6)
          << "sv " << sat.sv_id;
      // Velocity: +0.1 m/s along each axis.
      dx.setZero();
      dx[layout::kVel.index + axis] = 0.1;
      const auto pv = navbus::core::predictRange(
          perturbed(s, Eigen::Vector3d::Zero(), 0.1 * Eigen::Vector3d::Unit(axis)), 100.0, 2.0,
          sat);
      EXPECT_NEAR(pv.pseudorange_rate_mps - p0.pseudorange_rate_mps, (p0.h_rate * dx)(0, 0), 1e-9);
    }
    // Clock bias and drift enter with unit coefficients.
    EXPECT_DOUBLE_EQ(
        navbus::core::predictRange(s, 101.0, 2.0, sat).pseudorange_m - p0.pseudorange_m,
        p0.h_range(0, layout::kClockBias.index));
    EXPECT_DOUBLE_EQ(navbus::core::predictRange(s, 100.0, 2.5, sat).pseudorange_rate_mps -
                         p0.pseudorange_rate_mps,
                     0.5 * p0.h_rate(0, layout::kClockDrift.index));
  }
}

TEST(JosephUpdate, PseudorangesReduceAConstructedPositionAndClockError) {
  // Given an estimate 30 m off in position and 200 m in clock bias, with a matching covariance,
  const auto truth = ins();
  const auto sats = satellites(truth);
  StateVec err_true = StateVec::Zero();
  err_true.segment<3>(layout::kPos.index) << 20.0, -15.0, 16.0;
  err_true[layout::kClockBias.index] = 200.0;
  StateMat P = StateMat::Identity() * 1e-2;
  P.block<3, 3>(layout::kPos.index, layout::kPos.index) *= 1e5;  // 30 m sigma
  P(layout::kClockBias.index, layout::kClockBias.index) = 300.0 * 300.0;
  StateVec x = StateVec::Zero();
  const double before = (x - err_true).segment<4>(0).norm() + std::abs(x[15] - err_true[15]);
  // when noise-free pseudoranges (innovations H dx) of every satellite are processed,
  for (const auto& sat : sats) {
    const auto p = navbus::core::predictRange(truth, 0.0, 0.0, sat);
    const auto res = navbus::core::scalarUpdate<layout::kSize>(
        x, P, p.h_range, (p.h_range * err_true)(0, 0), 1.0, 5.0);
    EXPECT_TRUE(res.accepted);
  }
  // then the estimated errors approach the true ones and P stays symmetric positive definite.
  const double after = (x - err_true).segment<4>(0).norm() + std::abs(x[15] - err_true[15]);
  std::printf("constructed pseudorange update: error %.1f m -> %.3f m with %zu satellites\n",
              before, after, sats.size());
  EXPECT_LT(after, 0.05 * before);
  EXPECT_LT((P - P.transpose()).norm(), 1e-9);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<StateMat>(P).eigenvalues().minCoeff(), 0.0);
}

TEST(JosephUpdate, ConsiderStatesAreNotCorrectedButKeepTheirCorrelations) {
  // Given two correlated states, the second a consider state (Schmidt-Kalman), and a
  // measurement of their sum,
  Eigen::Matrix<double, 2, 1> x = Eigen::Matrix<double, 2, 1>::Zero();
  Eigen::Matrix2d P;
  P << 4.0, 1.0, 1.0, 2.0;
  const Eigen::Matrix<double, 1, 2> h(1.0, 1.0);
  const std::bitset<2> estimated("01");
  const Eigen::Matrix2d P0 = P;
  navbus::core::scalarUpdate<2>(x, P, h, 3.0, 1.0, 0.0, &estimated);
  // then only the first state is corrected, with the gain of a filter that sees the second
  // one's uncertainty: K = [P h^T]_0 / V, V = h P h^T + r = 9,
  EXPECT_DOUBLE_EQ(x[1], 0.0);
  EXPECT_DOUBLE_EQ(x[0], 5.0 / 9.0 * 3.0);
  // the consider state's variance is unchanged (nothing corrects it), and the covariance is
  // that of the Joseph form with this gain.
  const Eigen::Vector2d K(5.0 / 9.0, 0.0);
  const Eigen::Matrix2d A = Eigen::Matrix2d::Identity() - K * h;
  const Eigen::Matrix2d expected = A * P0 * A.transpose() + K * K.transpose();
  EXPECT_NEAR(P(1, 1), 2.0, 1e-15);
  EXPECT_LT((P - expected).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(JosephUpdate, StaysSymmetricPositiveDefiniteAndGatesOutliers) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  StateMat A;
  for (int i = 0; i < layout::kSize; ++i)
    for (int j = 0; j < layout::kSize; ++j) A(i, j) = n(rng);
  StateMat P = A * A.transpose() + StateMat::Identity();
  StateVec x = StateVec::Zero();
  for (int k = 0; k < 500; ++k) {
    Eigen::Matrix<double, 1, layout::kSize> h;
    for (int j = 0; j < layout::kSize; ++j) h(0, j) = n(rng);
    navbus::core::scalarUpdate<layout::kSize>(x, P, h, n(rng), 1e-4, 1e6);
  }
  EXPECT_LT((P - P.transpose()).norm(), 1e-9 * P.norm());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<StateMat>(P).eigenvalues().minCoeff(), 0.0);
  // An outlier far outside the gate is rejected, reported with its ratio, and changes nothing.
  const StateVec x0 = x;
  const StateMat P0 = P;
  Eigen::Matrix<double, 1, layout::kSize> h = Eigen::Matrix<double, 1, layout::kSize>::Zero();
  h(0, 0) = 1.0;
  const auto res = navbus::core::scalarUpdate<layout::kSize>(x, P, h, 1e6, 1.0, 5.0);
  EXPECT_FALSE(res.accepted);
  EXPECT_GT(res.test_ratio, 1.0);
  EXPECT_EQ(x, x0);
  EXPECT_EQ(P, P0);
}

#include "navbus/core/ins/imu_correction.hpp"
#include "navbus/core/ins/ins_error_model.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/sim/trajectory.hpp"

namespace {
/// Error of `est` relative to `truth` in the state layout's convention (position NED m, velocity,
/// phi with C_est = (I - [phi x]) C_true).
StateVec errorOf(const navbus::core::NavState& est, const navbus::core::NavState& truth) {
  StateVec e = StateVec::Zero();
  const earth::Radii r = earth::radiiOfCurvature(truth.position.latitude_rad);
  e[layout::kPos.index] = (est.position.latitude_rad - truth.position.latitude_rad) *
                          (r.meridian_m + truth.position.height_m);
  e[layout::kPos.index + 1] = (est.position.longitude_rad - truth.position.longitude_rad) *
                              (r.prime_vertical_m + truth.position.height_m) *
                              std::cos(truth.position.latitude_rad);
  e[layout::kPos.index + 2] = -(est.position.height_m - truth.position.height_m);
  e.segment<3>(layout::kVel.index) = est.vel_ned_mps - truth.vel_ned_mps;
  const Eigen::Matrix3d M =
      est.q_b_to_n.toRotationMatrix() * truth.q_b_to_n.toRotationMatrix().transpose();
  e.segment<3>(layout::kAtt.index) =
      Eigen::Vector3d(M(1, 2) - M(2, 1), M(2, 0) - M(0, 2), M(0, 1) - M(1, 0)) / 2.0;
  return e;
}
}  // namespace

namespace {
/// Mechanizes the truth and an estimate started at the error dx0 (position, velocity,
/// attitude; its bias and scale-factor estimates are the truth's plus dx0's errors) from the same
/// perfect increments of `traj`, and expects the linear prediction Phi dx0 of every navigation
/// block to match their nonlinear difference within `tolerance` (relative).
void expectLinearPredictionMatches(navbus::sim::Trajectory& traj, earth::GravityModel gravity,
                                   const StateVec& dx0, int steps, double dt, double tolerance,
                                   const char* label) {
  navbus::core::StrapdownNed truth(gravity);
  navbus::core::StrapdownNed est(gravity);
  truth.initialize(traj.state());
  navbus::core::NavState s0 = perturbed(traj.state(), dx0.segment<3>(layout::kPos.index),
                                        dx0.segment<3>(layout::kVel.index));
  s0.q_b_to_n =
      navbus::core::quaternionFromRotationVector(-dx0.segment<3>(layout::kAtt.index)) * s0.q_b_to_n;
  est.initialize(s0);
  StateMat Phi = StateMat::Identity();
  for (int k = 1; k <= steps; ++k) {
    const auto inc = traj.advance(dt);
    navbus::core::ImuIncrement m{static_cast<std::int64_t>(std::llround(k * dt * 1e9)), dt,
                                 inc.delta_vel_b_mps, inc.delta_angle_b_rad};
    // The truth's state at the start of the step drives F.
    Phi = navbus::core::transitionMatrix(
              navbus::core::errorDynamics(truth.state(), inc.delta_vel_b_mps / dt,
                                          inc.delta_angle_b_rad / dt, gravity),
              dt) *
          Phi;
    truth.propagate(m);
    // The estimate corrects its increments with its bias and scale-factor estimates (the
    // truth's, 0, plus the error).
    const navbus::core::ImuCorrection estimated{
        dx0.segment<3>(layout::kAccelBias.index), dx0.segment<3>(layout::kGyroBias.index),
        dx0.segment<3>(layout::kAccelScale.index), dx0.segment<3>(layout::kGyroScale.index)};
    est.propagate(estimated.applied(m));
  }
  const StateVec actual = errorOf(est.state(), truth.state());
  const StateVec predicted = Phi * dx0;
  for (const auto& b : {layout::kPos, layout::kVel, layout::kAtt}) {
    const double rel = (predicted.segment<3>(b.index) - actual.segment<3>(b.index)).norm() /
                       actual.segment<3>(b.index).norm();
    std::printf(
        "%s, error model block at %d: actual %.4e, predicted %.4e, relative difference "
        "%.2f %%\n",
        label, b.index, actual.segment<3>(b.index).norm(), predicted.segment<3>(b.index).norm(),
        100 * rel);
    EXPECT_LT(rel, tolerance) << label << ", block at " << b.index;
  }
}
}  // namespace

TEST(InsErrorModel, TransitionMatrixPredictsTheNonlinearErrorGrowth) {
  // Given a banked turn at 150 m/s and an estimate with position, velocity, attitude and bias
  // errors, both mechanized from the same perfect increments for 30 s,
  navbus::sim::VehicleStart start;
  start.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 3000.0};
  start.speed_mps = 150.0;
  std::vector<navbus::sim::Segment> segs(2);
  segs[0].duration_s = 3.0;
  segs[0].roll_rate_radps = 10.0 * M_PI / 180;
  segs[1].duration_s = 60.0;
  segs[1].heading_rate_radps = segs[1].yaw_rate_radps = 3.0 * M_PI / 180;
  navbus::sim::VehicleTrajectory traj(start, segs, earth::GravityModel::kWgs84Normal);
  StateVec dx0 = StateVec::Zero();
  dx0.segment<3>(layout::kPos.index) << 10.0, -5.0, 3.0;
  dx0.segment<3>(layout::kVel.index) << 0.1, -0.05, 0.02;
  dx0.segment<3>(layout::kAtt.index) << 1e-4, -2e-4, 5e-4;
  dx0.segment<3>(layout::kAccelBias.index) << 1e-3, -5e-4, 2e-3;
  dx0.segment<3>(layout::kGyroBias.index) << 1e-6, -2e-6, 3e-6;
  // then the linear prediction Phi dx0 matches the nonlinear difference within a few percent.
  expectLinearPredictionMatches(traj, earth::GravityModel::kWgs84Normal, dx0, 3000, 0.01, 0.03,
                                "aircraft");
}

TEST(InsErrorModel, TransitionMatrixPredictsTheErrorGrowthOfScaleFactors) {
  // Given a car-like drive (a 20 s acceleration, a 90 deg turn at 9 deg/s, a roll-in) and an
  // estimate whose only errors are scale factors on every accelerometer and gyro axis (the F
  // columns -C_b_n diag(f_b) and C_b_n diag(w_ib_b)), both mechanized from the same perfect
  // increments for 30 s,
  navbus::sim::VehicleStart start;
  start.position = {40.1 * M_PI / 180, -105.1 * M_PI / 180, 1580.0};
  start.speed_mps = 5.0;
  std::vector<navbus::sim::Segment> segs(3);
  segs[0].duration_s = 10.0;
  segs[0].accel_mps2 = 1.0;
  segs[1].duration_s = 2.0;
  segs[1].roll_rate_radps = 2.0 * M_PI / 180;
  segs[2].duration_s = 20.0;
  segs[2].heading_rate_radps = segs[2].yaw_rate_radps = 9.0 * M_PI / 180;
  navbus::sim::VehicleTrajectory traj(start, segs, earth::GravityModel::kWgs84Normal);
  StateVec dx0 = StateVec::Zero();
  dx0.segment<3>(layout::kAccelScale.index) << 2e-3, -1e-3, 3e-3;
  dx0.segment<3>(layout::kGyroScale.index) << -2e-3, 4e-3, 1e-2;
  // then the linear prediction Phi dx0 matches the nonlinear difference within a few percent.
  expectLinearPredictionMatches(traj, earth::GravityModel::kWgs84Normal, dx0, 3000, 0.01, 0.03,
                                "car, scale factors");
}

TEST(InsErrorModel, TransitionMatrixPredictsTheErrorGrowthInOrbit) {
  // Given seed 001's circular orbit (7.6 km/s: the transport rate and its dependence on the
  // position and velocity errors are 50 times an aircraft's) and an estimate with position,
  // velocity and attitude errors, both mechanized from the same perfect increments for 600 s,
  navbus::sim::CircularOrbitTrajectory traj{navbus::sim::OrbitStart{}};
  StateVec dx0 = StateVec::Zero();
  dx0.segment<3>(layout::kPos.index) << 10.0, -5.0, 3.0;
  dx0.segment<3>(layout::kVel.index) << 0.01, -0.005, 0.002;
  dx0.segment<3>(layout::kAtt.index) << 1e-4, -2e-4, 5e-4;
  // then the linear prediction Phi dx0 matches the nonlinear difference within a few percent
  // in every navigation block (the low-speed model was 41 % and 113 % off in position and
  // velocity).
  expectLinearPredictionMatches(traj, earth::GravityModel::kPointMass, dx0, 60000, 0.01, 0.03,
                                "orbit");
}

TEST(SparseRows, ProductsEqualTheDenseOnesForTransitionMatrices) {
  // Given transition matrices of the error model at random states (and one with states switched
  // off, rows and columns of Phi zeroed as the error state does) and a random covariance,
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    navbus::core::NavState s = ins();
    s.vel_ned_mps = 200.0 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    s.q_b_to_n =
        navbus::core::quaternionFromRotationVector(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const StateMat F = navbus::core::errorDynamics(s, Eigen::Vector3d(u(rng), u(rng), -9.8),
                                                   0.1 * Eigen::Vector3d(u(rng), u(rng), u(rng)),
                                                   earth::GravityModel::kWgs84Normal);
    StateMat Phi = navbus::core::transitionMatrix(F, 0.005);
    if (trial % 2 == 1) {
      Phi.row(layout::kClockBias.index).setZero();
      Phi.col(layout::kClockBias.index).setZero();
    }
    const StateMat A = StateMat::Random();
    const StateMat P = A * A.transpose();
    const navbus::core::SparseRows<layout::kSize> sparse(Phi);
    // then Phi P Phi^T, Phi P, Phi x and Phi Phi agree with the dense products to rounding,
    const StateMat dense = Phi * P * Phi.transpose();
    const StateMat sandwich = sparse.sandwichBlockTriangular<layout::kCoupledSize>(P);
    EXPECT_LT((sandwich - dense).cwiseAbs().maxCoeff(), 1e-12 * dense.cwiseAbs().maxCoeff());
    EXPECT_LT((sparse.times(P) - Phi * P).cwiseAbs().maxCoeff(), 1e-12 * P.cwiseAbs().maxCoeff());
    const StateVec x = StateVec::Random();
    EXPECT_LT((sparse.times(x) - Phi * x).cwiseAbs().maxCoeff(), 1e-12);
    StateMat PhiPhi = StateMat::Zero();
    sparse.addProductTo(sparse, 1.0, PhiPhi);
    EXPECT_LT((PhiPhi - Phi * Phi).cwiseAbs().maxCoeff(), 1e-12);
    // the covariance is exactly symmetric, and most of Phi is skipped;
    EXPECT_EQ(sandwich, sandwich.transpose());
    EXPECT_LT(sparse.nonZeros(), layout::kSize * layout::kSize / 2);
    // the structural patterns cover F and Phi, and give the same products.
    EXPECT_TRUE(navbus::core::errorDynamicsPattern().covers(F));
    EXPECT_TRUE(navbus::core::transitionPattern().covers(Phi));
    const navbus::core::SparseRows<layout::kSize> structural(Phi,
                                                             navbus::core::transitionPattern());
    EXPECT_EQ(structural.sandwichBlockTriangular<layout::kCoupledSize>(P), sandwich);
    // A running product of transitions kept transposed, C^T <- C^T Phi^T, equals the dense one.
    const StateMat Ct = (Phi * Phi).transpose();
    EXPECT_LT(
        (structural.timesTransposedBlockTriangular<layout::kCoupledSize>(Ct) - Ct * Phi.transpose())
            .cwiseAbs()
            .maxCoeff(),
        1e-12);
    // Phi is block upper triangular at the coupled size (no navigation error drives a bias or
    // the clock), and at no smaller one.
    EXPECT_TRUE(navbus::core::transitionPattern().isBlockUpperTriangular(layout::kCoupledSize));
    EXPECT_FALSE(
        navbus::core::transitionPattern().isBlockUpperTriangular(layout::kCoupledSize - 1));
  }
}

namespace {
/// Column i of B A^T as SparseRows' documentation defines it, one scalar product and sum at a
/// time in the pattern's (ascending) order: out(r) = sum_k A(i, k) B(r, k - offset).
template <class Matrix>
Eigen::VectorXd scalarColumnSum(const StateMat& A, int i, const Matrix& B, int offset = 0) {
  Eigen::VectorXd c = Eigen::VectorXd::Zero(B.rows());
  for (int k = 0; k < layout::kSize; ++k) {
    if (A(i, k) == 0.0) continue;
    for (Eigen::Index r = 0; r < B.rows(); ++r) c(r) += A(i, k) * B(r, k - offset);
  }
  return c;
}
}  // namespace

TEST(SparseRows, ProductsAreTheScalarSumsInThePatternsOrderBitForBit) {
  // Given a transition matrix and a covariance,
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  navbus::core::NavState s = ins();
  s.vel_ned_mps = 150.0 * Eigen::Vector3d(u(rng), u(rng), u(rng));
  const StateMat Phi = navbus::core::transitionMatrix(
      navbus::core::errorDynamics(s, Eigen::Vector3d(u(rng), u(rng), -9.8),
                                  0.1 * Eigen::Vector3d(u(rng), u(rng), u(rng)),
                                  earth::GravityModel::kWgs84Normal),
      0.01);
  const StateMat A = StateMat::Random();
  const StateMat P = A * A.transpose();
  const navbus::core::SparseRows<layout::kSize> sparse(Phi);
  constexpr int kLead = layout::kCoupledSize;
  constexpr int kTrail = layout::kSize - kLead;
  // then B Phi^T is the scalar sums exactly (not to rounding: the same operations in the same
  // order),
  StateMat times_t;
  for (int i = 0; i < layout::kSize; ++i) times_t.col(i) = scalarColumnSum(Phi, i, P);
  EXPECT_EQ(sparse.timesTransposed(P), times_t);
  // and so are Phi P Phi^T's steps (W^T = P Phi(0:Lead, :)^T, then W Phi^T's leading rows, the
  // trailing block from P22) and the block triangular running product.
  Eigen::Matrix<double, layout::kSize, kLead> wt;
  for (int i = 0; i < kLead; ++i) wt.col(i) = scalarColumnSum(Phi, i, P);
  const Eigen::Matrix<double, kLead, layout::kSize> w = wt.transpose();
  Eigen::Matrix<double, kTrail, kTrail> tt;
  const Eigen::Matrix<double, kTrail, kTrail> p22 = P.bottomRightCorner<kTrail, kTrail>();
  for (int i = kLead; i < layout::kSize; ++i)
    tt.col(i - kLead) = scalarColumnSum(Phi, i, p22, kLead);
  const Eigen::Matrix<double, kTrail, kTrail> t = tt.transpose();
  // (the upper triangle is computed, the lower one mirrored from it).
  const StateMat sandwich = sparse.sandwichBlockTriangular<kLead>(P);
  EXPECT_EQ(sandwich, sandwich.transpose());
  for (int j = 0; j < layout::kSize; ++j) {
    const Eigen::VectorXd lead = scalarColumnSum(Phi, j, w);
    const Eigen::VectorXd trail =
        j >= kLead ? scalarColumnSum(Phi, j, t, kLead) : Eigen::VectorXd();
    for (int i = 0; i <= j; ++i) {
      const double expected = i < kLead ? lead(i) : trail(i - kLead);
      EXPECT_EQ(sandwich(i, j), expected) << "(" << i << ", " << j << ")";
    }
  }
  const StateMat ct = (Phi * Phi).transpose();
  const StateMat running = sparse.timesTransposedBlockTriangular<kLead>(ct);
  for (int i = kLead; i < layout::kSize; ++i) {
    const Eigen::Matrix<double, kTrail, layout::kSize> ct2 = ct.bottomRows<kTrail>();
    EXPECT_EQ(Eigen::VectorXd(running.col(i).tail<kTrail>()), scalarColumnSum(Phi, i, ct2)) << i;
  }
}

TEST(ErrorState, InactiveStatesKeepTheirVarianceAndStayOutOfTheCoupling) {
  // Given an error state whose clock and star-tracker bias are inactive, a covariance with
  // cross terms everywhere, and a transition that couples the clock (bias from drift) and
  // decays the star-tracker bias,
  namespace core = navbus::core;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  core::NavState s = ins();
  s.q_b_to_n = core::quaternionFromRotationVector(Eigen::Vector3d(0.3, -0.2, 1.1));
  StateMat Phi = core::transitionMatrix(
      core::errorDynamics(s, Eigen::Vector3d(0.2, 0.1, -9.8), Eigen::Vector3d(0.01, 0.02, -0.03),
                          earth::GravityModel::kWgs84Normal),
      0.01);
  for (int i = layout::kStarTrackerBias.index; i < layout::kStarTrackerBias.end(); ++i)
    Phi(i, i) = 0.9;
  const StateMat A = StateMat::Random();
  const StateMat P0 = A * A.transpose() + StateMat::Identity();
  const core::StateMask active = core::maskOf(
      {layout::kPos, layout::kVel, layout::kAtt, layout::kAccelBias, layout::kGyroBias});
  core::ErrorState es;
  es.initialize(P0, active);
  StateVec x0;
  for (int i = 0; i < layout::kSize; ++i) x0[i] = active[static_cast<std::size_t>(i)] ? u(rng) : 0;
  es.x() = x0;
  const StateVec q = StateVec::Constant(1e-3);
  // when it predicts,
  const StateMat P_before = es.P();
  es.predict(Phi, q);
  // then it is the dense prediction with the inactive states cut out of Phi (rows and columns
  // zeroed, a unit diagonal) and no process noise on them:
  StateMat Phi_reduced = Phi;
  StateVec q_reduced = q;
  for (int i = 0; i < layout::kSize; ++i) {
    if (active[static_cast<std::size_t>(i)]) continue;
    Phi_reduced.row(i).setZero();
    Phi_reduced.col(i).setZero();
    Phi_reduced(i, i) = 1.0;
    q_reduced[i] = 0.0;
  }
  StateMat expected = Phi_reduced * P_before * Phi_reduced.transpose();
  expected.diagonal() += q_reduced;
  EXPECT_LT((es.P() - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  EXPECT_LT((es.x() - Phi_reduced * x0).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(es.P(), es.P().transpose());
  // the inactive variances are exactly those before, and no cross term reaches them.
  for (int i = 0; i < layout::kSize; ++i) {
    if (active[static_cast<std::size_t>(i)]) continue;
    EXPECT_EQ(es.P()(i, i), P_before(i, i)) << "state " << i;
    EXPECT_EQ(es.P().row(i).cwiseAbs().sum(), std::abs(P_before(i, i))) << "state " << i;
  }
}
