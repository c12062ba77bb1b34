// The GNSS fix's time-correlated position error (loose coupling, layout::kFixPositionError):
// its column of H against the numerical difference of the innovation, its column of Phi (the
// Gauss-Markov decay and the stationary variance), and a filter that learns a fix offset into
// the state instead of its position.
#include <cmath>

#include <gtest/gtest.h>

#include "navbus/core/filter/aiding_measurements.hpp"
#include "navbus/core/filter/integrated_filter.hpp"

namespace earth = navbus::core::earth;
namespace layout = navbus::core::layout;

namespace {

navbus::core::NavState parkedCar() {
  navbus::core::NavState s;
  s.time_ns = 1'400'000'000'000'000'000;
  s.position = {40.0966 * M_PI / 180, -105.1474 * M_PI / 180, 1580.0};
  return s;
}

navbus::core::FilterTuning fixErrorTuning() {
  navbus::core::FilterTuning t;
  t.pos_sigma_m = 1.0;
  t.vel_sigma_mps = 0.1;
  t.gate_sigma = 0.0;
  t.fix_position_error_sigma_h_m = 0.05;
  t.fix_position_error_sigma_v_m = 0.10;
  t.fix_position_error_correlation_time_s = 30.0;
  return t;
}

navbus::core::StateMask fixErrorMask() {
  using namespace layout;
  return navbus::core::maskOf({kPos, kVel, kAtt, kAccelBias, kGyroBias, kFixPositionError});
}

}  // namespace

TEST(FixPositionError, TheInnovationMovesOneForOneWithTheEstimate) {
  // H's columns on the fix error are the numerical derivative of z: each estimate component
  // moved by 1 cm moves its own row by 1 cm and no other.
  const navbus::core::NavState ins = parkedCar();
  const earth::Geodetic fix = earth::offsetNed(ins.position, Eigen::Vector3d(0.3, -0.2, 0.1));
  const Eigen::Vector3d lever_b(0.0, -0.05, -0.65);
  const Eigen::Vector3d sigma(0.02, 0.02, 0.04);
  const Eigen::Vector3d b(0.04, -0.03, 0.02);
  const auto m = navbus::core::positionMeasurement(ins, fix, sigma, lever_b, &b);
  const auto without = navbus::core::positionMeasurement(ins, fix, sigma, lever_b);
  EXPECT_TRUE(m.z.isApprox(without.z + b, 1e-12));
  const double step = 0.01;
  for (int j = 0; j < 3; ++j) {
    Eigen::Vector3d moved = b;
    moved[j] += step;
    const auto mj = navbus::core::positionMeasurement(ins, fix, sigma, lever_b, &moved);
    const Eigen::Vector3d numerical = (mj.z - m.z) / step;
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(m.h(i, layout::kFixPositionError.index + j), numerical[i], 1e-9)
          << "row " << i << ", state " << j;
    }
  }
  // Without the estimate the measurement has no fix-error columns.
  EXPECT_TRUE((without.h.block<3, 3>(0, layout::kFixPositionError.index).isZero()));
}

TEST(FixPositionError, DecaysAsAGaussMarkovProcessAndKeepsItsStationaryVariance) {
  // A parked car whose fixes read 8 cm north: part of it goes to the fix's error state. With
  // the fixes gone for 20 s the estimate falls by exp(-T / tau) and its variance relaxes
  // towards sigma^2 by the same law, per axis with its own sigma.
  navbus::core::FilterTuning t = fixErrorTuning();
  t.pos_sigma_m = 0.02;  // a car that knows where it parked: the offset is the fixes'
  const navbus::core::NavState truth = parkedCar();
  navbus::core::IntegratedFilter f;
  f.initialize(truth, 0.0, 0.0, t, fixErrorMask());
  ASSERT_TRUE(f.modelsFixPositionError());
  const earth::Geodetic fix = earth::offsetNed(truth.position, Eigen::Vector3d(0.08, 0.0, 0.0));
  for (int k = 0; k < 3; ++k) {
    f.update(navbus::core::positionMeasurement(f.state(), fix, Eigen::Vector3d::Constant(0.02),
                                               Eigen::Vector3d::Zero(), &f.fixPositionError()),
             navbus::core::AidingKind::kPosition);
  }
  const int north = layout::kFixPositionError.index;
  const double e0 = f.fixPositionError().x();
  const double v0 = f.covariance()(north, north);
  EXPECT_GT(e0, 0.03);  // most of the 8 cm (the fixes' 2 cm and the position's share the rest)
  const double sigma2_h = t.fix_position_error_sigma_h_m * t.fix_position_error_sigma_h_m;
  const double sigma2_v = t.fix_position_error_sigma_v_m * t.fix_position_error_sigma_v_m;
  ASSERT_LT(v0, 0.99 * sigma2_h);
  const double vd0 = f.covariance()(north + 2, north + 2);
  navbus::core::ImuIncrement inc;
  inc.interval_s = 0.01;
  const int steps = 2000;  // 20 s
  for (int k = 0; k < steps; ++k) {
    inc.time_ns = truth.time_ns + static_cast<std::int64_t>(k + 1) * 10'000'000;
    f.propagate(inc);
  }
  const double decay = std::exp(-steps * inc.interval_s / t.fix_position_error_correlation_time_s);
  EXPECT_NEAR(f.fixPositionError().x(), e0 * decay, 1e-12 * std::abs(e0));
  EXPECT_NEAR(f.covariance()(north, north), decay * decay * v0 + sigma2_h * (1.0 - decay * decay),
              1e-9 * sigma2_h);
  EXPECT_NEAR(f.covariance()(north + 2, north + 2),
              decay * decay * vd0 + sigma2_v * (1.0 - decay * decay), 1e-9 * sigma2_v);
}

TEST(FixPositionError, NotModelledWithoutItsSigmaOrBesidePseudorangeErrors) {
  navbus::core::FilterTuning t = fixErrorTuning();
  t.fix_position_error_sigma_h_m = 0.0;
  navbus::core::IntegratedFilter f;
  f.initialize(parkedCar(), 0.0, 0.0, t, fixErrorMask());
  EXPECT_FALSE(f.modelsFixPositionError());
  t = fixErrorTuning();
  t.pseudorange_error_sigma_m = 5.0;  // the block holds the satellites' errors then
  f.initialize(parkedCar(), 0.0, 0.0, t, fixErrorMask());
  EXPECT_FALSE(f.modelsFixPositionError());
}
