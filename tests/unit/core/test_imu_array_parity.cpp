// The parity test of an array of IMUs (imu_array_parity.hpp) on a rotating rigid body: three
// tilted units 0.4 m apart with their own constant biases and noise. The learned parity mean takes
// the biases out, the lever-arm term the rotation's specific force at each place (without it the
// accelerometers alarm), a step on one unit's accelerometer axis is isolated to that unit and axis,
// and the test goes on without it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "navbus/core/integrity/imu_array_parity.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/units.hpp"
#include "rotating_imu_array.hpp"

namespace nc = navbus::core;
namespace nu = navbus::units;
using nc::ImuArrayParity;
using nc::ImuInstrument;

namespace {

using navbus::test::kArrayDt;
using navbus::test::RotatingBody;
using navbus::test::triplexUnits;

nc::ImuArrayParityConfig arrayConfig() {
  nc::ImuArrayParityConfig c;
  c.glr.false_alarm_probability = 1e-9;
  c.reference_samples = 1000;
  return c;
}

ImuArrayParity makeArray(const std::vector<nc::ImuArrayUnit>& units) {
  std::string error;
  auto a = ImuArrayParity::make(units, kArrayDt, arrayConfig(), error);
  EXPECT_TRUE(a.has_value()) << error;
  return *a;
}

/// Samples until the first detection of `kind` (or `count` samples): its index, -1 if none.
int firstDetection(ImuArrayParity& a, RotatingBody& body, int count, ImuInstrument kind,
                   nc::ImuArrayDetection* out = nullptr, int unit = -1, int axis = 0,
                   double step = 0.0) {
  for (int i = 0; i < count; ++i) {
    const auto& r = a.update(body.next(unit, axis, step));
    if (const auto& d = r.detections[static_cast<std::size_t>(kind)]) {
      if (out) *out = *d;
      return i;
    }
  }
  return -1;
}

}  // namespace

TEST(ImuArrayParity, LearnsTheBiasesThenIsolatesAStepOnOneUnitsAccelerometerAxis) {
  // Given three tilted units 0.4 m apart on a body turning at up to 0.3 rad/s, with constant
  // biases up to 1 deg/h and 1 mg and seed 000's noise, when the array has learned its parity
  // mean (1000 samples) and runs 6000 fault-free samples, then neither kind detects anything;
  // when unit 1's accelerometer z takes a step of 5 minimum detectable biases, then it is
  // detected within the 200-sample window, named (unit 1, axis z, not ambiguous), its size within
  // 4 sigma; and once it is excluded the other eight accelerometers test on without alarm.
  const auto units = triplexUnits();
  ImuArrayParity array = makeArray(units);
  RotatingBody body(units);
  for (int i = 0; i < 1000; ++i) EXPECT_TRUE(array.update(body.next()).learning);
  for (int i = 0; i < 6000; ++i) {
    const auto& r = array.update(body.next());
    ASSERT_FALSE(r.learning);
    ASSERT_FALSE(r.detections[0] || r.detections[1])
        << "sample " << i << ": gyro l " << r.statistic[0] << " accel l " << r.statistic[1];
  }
  const double mdb = array.minimumDetectableBias(ImuInstrument::kAccelerometer, 1, 2);
  EXPECT_GT(mdb, 50 * nu::kMicroG);
  EXPECT_LT(mdb, 150 * nu::kMicroG);
  nc::ImuArrayDetection d;
  const int after =
      firstDetection(array, body, 400, ImuInstrument::kAccelerometer, &d, 1, 2, 5.0 * mdb);
  ASSERT_GE(after, 0);
  EXPECT_LT(after, 200);
  EXPECT_EQ(d.unit, 1);
  EXPECT_EQ(d.axis, 2);
  EXPECT_FALSE(d.glr.ambiguous);
  EXPECT_NEAR(d.magnitude, 5.0 * mdb, 4.0 * d.magnitude_sigma);
  ASSERT_TRUE(array.exclude(ImuInstrument::kAccelerometer, 1, 2));
  EXPECT_EQ(array.instruments(ImuInstrument::kAccelerometer), 8);
  EXPECT_EQ(array.minimumDetectableBias(ImuInstrument::kAccelerometer, 1, 2), 0.0);
  EXPECT_EQ(
      firstDetection(array, body, 3000, ImuInstrument::kAccelerometer, nullptr, 1, 2, 5.0 * mdb),
      -1);
  EXPECT_EQ(firstDetection(array, body, 1000, ImuInstrument::kGyro), -1);
}

TEST(ImuArrayParity, WithoutTheLeverArmsTheRotationAlarmsTheAccelerometers) {
  // Given the same body and units, when the array is told the units sit at the origin, then the
  // rotation's specific force at 0.4 m (up to 0.04 m/s^2, hundreds of minimum detectable biases)
  // is a parity signal and the accelerometers alarm within the first 3000 samples of test.
  auto told = triplexUnits();
  for (auto& u : told) u.lever_arm_b_m.setZero();
  ImuArrayParity array = makeArray(told);
  RotatingBody body(triplexUnits());
  EXPECT_GE(firstDetection(array, body, 4000, ImuInstrument::kAccelerometer), 1000);
}

TEST(ImuArrayParity, TheLeverArmTermCarriesTheGyrosNoiseIntoTheAccelerometersSigmas) {
  // Given MEMS units (0.228 deg/sqrt(h), 70 ug/sqrt(Hz)) 0.5 m apart on the turning body, the
  // lever-arm term's first difference of the noisy rate adds about 4 times the accelerometers'
  // own noise to the units off the origin; when the array runs 20000 fault-free samples after
  // learning, then the accelerometers do not alarm (their sigmas include that noise), and an
  // off-origin unit's minimum detectable bias is larger than with the units together.
  auto units = triplexUnits();
  for (int u = 0; u < 3; ++u) {
    units[static_cast<std::size_t>(u)].gyro_sigma_rad =
        0.228 * nu::kDeg / 60.0 * std::sqrt(kArrayDt);
    units[static_cast<std::size_t>(u)].accel_sigma_mps = 70.0 * nu::kMicroG * std::sqrt(kArrayDt);
    units[static_cast<std::size_t>(u)].lever_arm_b_m =
        Eigen::Vector3d(0.5 * (u == 1) - 0.5 * (u == 2), 0, 0);
  }
  ImuArrayParity array = makeArray(units);
  RotatingBody body(units);
  for (int i = 0; i < 1000; ++i) array.update(body.next());
  EXPECT_EQ(firstDetection(array, body, 20000, ImuInstrument::kAccelerometer), -1);
  auto together = units;
  for (auto& u : together) u.lever_arm_b_m.setZero();
  const double apart = array.minimumDetectableBias(ImuInstrument::kAccelerometer, 1, 1);
  const double close =
      makeArray(together).minimumDetectableBias(ImuInstrument::kAccelerometer, 1, 1);
  EXPECT_GT(apart, 1.3 * close) << "0.5 m apart " << apart << ", together " << close;
}

TEST(ImuArrayParity, RefusesArraysItCannotMonitorNamingTheField) {
  std::string error;
  auto units = triplexUnits();
  EXPECT_FALSE(ImuArrayParity::make({units[0]}, kArrayDt, arrayConfig(), error));
  EXPECT_NE(error.find("1 units"), std::string::npos) << error;
  units[2].c_u_b(0, 0) = 2.0;
  error.clear();
  EXPECT_FALSE(ImuArrayParity::make(units, kArrayDt, arrayConfig(), error));
  EXPECT_NE(error.find("unit 2: the mounting is not a rotation"), std::string::npos) << error;
  units = triplexUnits();
  units[1].accel_sigma_mps = 0.0;
  error.clear();
  EXPECT_FALSE(ImuArrayParity::make(units, kArrayDt, arrayConfig(), error));
  EXPECT_NE(error.find("unit 1: the gyro and accelerometer noise"), std::string::npos) << error;
  units = triplexUnits();
  auto config = arrayConfig();
  config.glr.onsets = 0;
  error.clear();
  EXPECT_FALSE(ImuArrayParity::make(units, kArrayDt, config, error));
  EXPECT_NE(error.find("onsets is 0"), std::string::npos) << error;
}
