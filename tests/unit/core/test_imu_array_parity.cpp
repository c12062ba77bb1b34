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

namespace nc = navbus::core;
namespace nu = navbus::units;
using nc::ImuArrayParity;
using nc::ImuInstrument;

namespace {

constexpr double kArrayDt = 0.01;  ///< [s] 100 Hz

std::vector<nc::ImuArrayUnit> triplexUnits() {
  const double gyro_sigma = 0.001 * nu::kDeg / 60.0 * std::sqrt(kArrayDt);  // 0.001 deg/sqrt(h)
  const double accel_sigma = 10.0 * nu::kMicroG * std::sqrt(kArrayDt);      // 10 ug/sqrt(Hz)
  std::vector<nc::ImuArrayUnit> units(3);
  const Eigen::Vector3d rpy_deg[3] = {{0, 0, 0}, {35, 0, 45}, {0, -35, -45}};
  const Eigen::Vector3d arm_m[3] = {{0, 0, 0}, {0.4, 0, 0}, {-0.4, 0, 0}};
  for (int u = 0; u < 3; ++u) {
    units[u].c_u_b = nc::dcmFromEuler(rpy_deg[u] * nu::kDeg).transpose();
    units[u].lever_arm_b_m = arm_m[u];
    units[u].gyro_sigma_rad = gyro_sigma;
    units[u].accel_sigma_mps = accel_sigma;
  }
  return units;
}

/// Increments of a rotating, accelerating rigid body sensed by the units: rates in their axes,
/// specific force at their place (first-order dw/dt, as the simulator), constant biases and
/// white noise; `step_mps2` added to unit `step_unit`'s accelerometer `step_axis`.
class RotatingBody {
 public:
  explicit RotatingBody(std::vector<nc::ImuArrayUnit> units) : units_(std::move(units)) {
    for (auto& b : gyro_bias_) b = Eigen::Vector3d::Random() * nu::kDegPerHour;
    for (auto& b : accel_bias_) b = Eigen::Vector3d::Random() * nu::kMilliG;
  }

  std::array<nc::ImuIncrement, ImuArrayParity::kMaxUnits> next(int step_unit = -1,
                                                               int step_axis = 0,
                                                               double step_mps2 = 0.0) {
    const double t = kArrayDt * static_cast<double>(++k_);
    const Eigen::Vector3d w(0.3 * std::sin(t), 0.2 * std::cos(0.7 * t), 0.1 * std::sin(1.3 * t));
    const Eigen::Vector3d w_dot =
        k_ > 1 ? Eigen::Vector3d((w - w_prev_) / kArrayDt) : Eigen::Vector3d::Zero();
    w_prev_ = w;
    const Eigen::Vector3d f(0.5 * std::cos(0.2 * t), -0.2, -9.8);
    std::array<nc::ImuIncrement, ImuArrayParity::kMaxUnits> out{};
    for (std::size_t u = 0; u < units_.size(); ++u) {
      const nc::ImuArrayUnit& unit = units_[u];
      const Eigen::Vector3d& r = unit.lever_arm_b_m;
      Eigen::Vector3d f_u = unit.c_u_b * (f + w_dot.cross(r) + w.cross(w.cross(r)));
      f_u += accel_bias_[u];
      if (static_cast<int>(u) == step_unit) f_u[step_axis] += step_mps2;
      out[u].interval_s = kArrayDt;
      out[u].delta_angle_b_rad =
          (unit.c_u_b * w + gyro_bias_[u]) * kArrayDt + noise(unit.gyro_sigma_rad);
      out[u].delta_vel_b_mps = f_u * kArrayDt + noise(unit.accel_sigma_mps);
    }
    return out;
  }

 private:
  Eigen::Vector3d noise(double sigma) {
    return Eigen::Vector3d(normal_(rng_), normal_(rng_), normal_(rng_)) * sigma;
  }
  std::vector<nc::ImuArrayUnit> units_;
  std::array<Eigen::Vector3d, 3> gyro_bias_, accel_bias_;
  Eigen::Vector3d w_prev_{Eigen::Vector3d::Zero()};
  long k_{0};
  std::mt19937_64 rng_{2026};
  std::normal_distribution<double> normal_{0.0, 1.0};
};

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
