// The least-squares combination of redundant IMUs (imu_array_combination.hpp) on the rotating
// rigid body of the parity tests: three tilted units 0.4 m apart. The combination is the body
// origin's motion plus the combined biases (lever arms removed), its noise is eq. 1's covariance
// (sigma / sqrt(3) per axis for three triads), an instrument taken out no longer counts, and one
// that would leave fewer than three spanning axes stays.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "navbus/core/ins/imu_array_combination.hpp"
#include "rotating_imu_array.hpp"

namespace nc = navbus::core;
using navbus::test::kArrayDt;
using navbus::test::RotatingBody;
using navbus::test::triplexUnits;
using nc::ImuArrayCombination;
using nc::ImuInstrument;
namespace nu = navbus::units;

namespace {

ImuArrayCombination makeCombination(const std::vector<nc::ImuArrayUnit>& units) {
  std::string error;
  auto c = ImuArrayCombination::make(units, kArrayDt, error);
  EXPECT_TRUE(c.has_value()) << error;
  return *c;
}

std::array<Eigen::Vector3d, ImuArrayCombination::kMaxUnits> biases(const RotatingBody& body,
                                                                   bool gyro) {
  std::array<Eigen::Vector3d, ImuArrayCombination::kMaxUnits> b{};
  for (std::size_t u = 0; u < 3; ++u) b[u] = gyro ? body.gyroBias(u) : body.accelBias(u);
  return b;
}

}  // namespace

TEST(ImuArrayCombination, IsTheBodyOriginsMotionPlusTheCombinedBiases) {
  const auto units = triplexUnits();
  ImuArrayCombination c = makeCombination(units);
  RotatingBody body(units);
  body.noiseless();
  const Eigen::Vector3d gyro_bias = c.combinedBias(ImuInstrument::kGyro, biases(body, true));
  const Eigen::Vector3d accel_bias =
      c.combinedBias(ImuInstrument::kAccelerometer, biases(body, false));
  // Equal weights, three triads: the combined bias is the mean of the biases in body axes.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t u = 0; u < 3; ++u) mean += units[u].c_u_b.transpose() * body.gyroBias(u) / 3.0;
  EXPECT_LT((gyro_bias - mean).norm(), 1e-15);
  for (int k = 0; k < 500; ++k) {
    const auto inc = c.combine(body.next(), 0b111);
    ASSERT_TRUE(inc.has_value());
    EXPECT_NEAR(inc->interval_s, kArrayDt, 0.0);
    EXPECT_LT((inc->delta_angle_b_rad / kArrayDt - body.rate_b() - gyro_bias).norm(), 1e-12);
    // The lever-arm term: first-order dw/dt, as the body's; exact but for the first sample.
    if (k > 0) {
      EXPECT_LT((inc->delta_vel_b_mps / kArrayDt - body.specificForce_b() - accel_bias).norm(),
                1e-9)
          << k;
    }
  }
}

TEST(ImuArrayCombination, HasTheNoiseOfTheLeastSquaresCovariance) {
  const auto units = triplexUnits();
  ImuArrayCombination c = makeCombination(units);
  const Eigen::Vector3d sigma = c.sigma(ImuInstrument::kGyro);
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(sigma[a], units[0].gyro_sigma_rad / std::sqrt(3.0), 1e-18);
  RotatingBody body(units);
  const Eigen::Vector3d gyro_bias = c.combinedBias(ImuInstrument::kGyro, biases(body, true));
  constexpr int kSamples = 20000;
  Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero();
  for (int k = 0; k < kSamples; ++k) {
    const auto inc = c.combine(body.next(), 0b111);
    const Eigen::Vector3d e = inc->delta_angle_b_rad - (body.rate_b() + gyro_bias) * kArrayDt;
    sum_sq += e.cwiseAbs2();
  }
  // The sample sigma of 20000 draws is within 2 % of the true one at 3.5 of its sigmas.
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(std::sqrt(sum_sq[a] / kSamples) / sigma[a], 1.0, 0.02) << "axis " << a;
}

TEST(ImuArrayCombination, AnInstrumentTakenOutNoLongerCountsAndTheBiasChanges) {
  const auto units = triplexUnits();
  ImuArrayCombination c = makeCombination(units);
  RotatingBody body(units);
  body.noiseless();
  const Eigen::Vector3d before = c.combinedBias(ImuInstrument::kGyro, biases(body, true));
  ASSERT_TRUE(c.exclude(ImuInstrument::kGyro, 1, 0));
  EXPECT_EQ(c.generation(), 1);
  EXPECT_FALSE(c.included(ImuInstrument::kGyro, 1, 0));
  EXPECT_FALSE(c.exclude(ImuInstrument::kGyro, 1, 0)) << "out already";
  const Eigen::Vector3d after = c.combinedBias(ImuInstrument::kGyro, biases(body, true));
  EXPECT_GT((after - before).norm(), 1e-3 * nu::kDegPerHour) << "the weights changed";
  // A 10 deg/h step on the excluded instrument does not reach the combination.
  for (int k = 0; k < 50; ++k) {
    auto sample = body.next();
    sample[1].delta_angle_b_rad.x() += 10.0 * nu::kDegPerHour * kArrayDt;
    const auto inc = c.combine(sample, 0b111);
    EXPECT_LT((inc->delta_angle_b_rad / kArrayDt - body.rate_b() - after).norm(), 1e-12);
  }
  // Eight gyros left: fewer sigma on no axis, more on at least one.
  const Eigen::Vector3d sigma = c.sigma(ImuInstrument::kGyro);
  EXPECT_GT(sigma.maxCoeff(), units[0].gyro_sigma_rad / std::sqrt(3.0) * 1.01);
}

TEST(ImuArrayCombination, KeepsAnInstrumentWhoseLossWouldLeaveNoThreeAxes) {
  std::vector<nc::ImuArrayUnit> units = triplexUnits();
  units.resize(2);
  units[1].c_u_b = units[0].c_u_b;  // two parallel units
  ImuArrayCombination c = makeCombination(units);
  ASSERT_TRUE(c.exclude(ImuInstrument::kGyro, 0, 2));
  EXPECT_FALSE(c.exclude(ImuInstrument::kGyro, 1, 2)) << "no z gyro would be left";
  EXPECT_TRUE(c.included(ImuInstrument::kGyro, 1, 2));
  EXPECT_EQ(c.generation(), 1);
  ASSERT_TRUE(c.excludeUnit(0)) << "unit 1 alone still spans";
  EXPECT_FALSE(c.excludeUnit(1)) << "nothing would be left";
  EXPECT_EQ(c.generation(), 2);
}

TEST(ImuArrayCombination, CombinesTheUnitsPresentAndRefusesABadArrayNamingTheField) {
  const auto units = triplexUnits();
  ImuArrayCombination c = makeCombination(units);
  RotatingBody body(units);
  body.noiseless();
  auto sample = body.next();
  sample[2].delta_angle_b_rad.setConstant(1.0);  // absent: whatever it holds is not read
  const auto inc = c.combine(sample, 0b011);
  ASSERT_TRUE(inc.has_value());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t u = 0; u < 2; ++u) mean += units[u].c_u_b.transpose() * body.gyroBias(u) / 2.0;
  EXPECT_LT((inc->delta_angle_b_rad / kArrayDt - body.rate_b() - mean).norm(), 1e-12);
  EXPECT_FALSE(c.combine(sample, 0).has_value());

  std::string error;
  EXPECT_FALSE(ImuArrayCombination::make({units[0]}, kArrayDt, error).has_value());
  EXPECT_NE(error.find("1 units"), std::string::npos) << error;
  auto bad = units;
  bad[2].accel_sigma_mps = -1.0;
  EXPECT_FALSE(ImuArrayCombination::make(bad, kArrayDt, error).has_value());
  EXPECT_NE(error.find("unit 2"), std::string::npos) << error;
}
