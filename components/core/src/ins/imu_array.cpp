#include "navbus/core/ins/imu_array.hpp"

#include <cmath>

#include <Eigen/LU>

namespace navbus::core {

namespace {

constexpr double kRotationTolerance = 1e-6;  ///< |C C^T - I| and |det C - 1| of a mounting

std::string unitField(std::size_t u, const char* field) {
  return "IMU array unit " + std::to_string(u) + ": " + field;
}

bool checkUnit(std::size_t u, const ImuArrayUnit& unit, std::string& error) {
  const Eigen::Matrix3d& c = unit.c_u_b;
  if (!c.allFinite() ||
      (c * c.transpose() - Eigen::Matrix3d::Identity()).norm() > kRotationTolerance ||
      std::abs(c.determinant() - 1.0) > kRotationTolerance) {
    error = unitField(u, "the mounting is not a rotation");
    return false;
  }
  if (!unit.lever_arm_b_m.allFinite()) {
    error = unitField(u, "lever_arm_b_m is not finite");
    return false;
  }
  if (!(unit.gyro_sigma_rad > 0.0) || !(unit.accel_sigma_mps > 0.0)) {
    error = unitField(u, "the gyro and accelerometer noise must be positive (gyro ") +
            std::to_string(unit.gyro_sigma_rad) + " rad, accelerometer " +
            std::to_string(unit.accel_sigma_mps) + " m/s per sample)";
    return false;
  }
  return true;
}

}  // namespace

bool checkImuArray(const std::vector<ImuArrayUnit>& units, double interval_s, int max_units,
                   std::string& error) {
  if (units.size() < 2 || units.size() > static_cast<std::size_t>(max_units)) {
    error = "IMU array: " + std::to_string(units.size()) + " units; it must have 2 to " +
            std::to_string(max_units);
    return false;
  }
  if (!(interval_s > 0.0) || !std::isfinite(interval_s)) {
    error = "IMU array: sample interval " + std::to_string(interval_s) + " s is not positive";
    return false;
  }
  for (std::size_t u = 0; u < units.size(); ++u)
    if (!checkUnit(u, units[u], error)) return false;
  return true;
}

}  // namespace navbus::core
