#include "navbus/core/math/rotation.hpp"

#include <cmath>

namespace navbus::core {

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(),  //
      a.z(), 0.0, -a.x(),   //
      -a.y(), a.x(), 0.0;
  return m;
}

Eigen::Quaterniond quaternionFromRotationVector(const Eigen::Vector3d& phi) {
  const double angle_sq = phi.squaredNorm();
  double c;  // cos(angle / 2)
  double k;  // sin(angle / 2) / angle
  if (angle_sq < 1e-6) {
    // Taylor series to fourth order: the first term left out (angle^6 / 46080 in the cosine)
    // is under 3e-23 below 1e-3 rad, so the series is exact in double precision there (a
    // 200 Hz increment at up to 0.2 rad/s, the NED frame's rotation over one) and costs no
    // sine and cosine.
    c = 1.0 - angle_sq / 8.0 + angle_sq * angle_sq / 384.0;
    k = 0.5 - angle_sq / 48.0 + angle_sq * angle_sq / 3840.0;
  } else {
    const double angle = std::sqrt(angle_sq);
    c = std::cos(0.5 * angle);
    k = std::sin(0.5 * angle) / angle;
  }
  return Eigen::Quaterniond(c, k * phi.x(), k * phi.y(), k * phi.z());
}

Eigen::Vector3d eulerFromDcm(const Eigen::Matrix3d& c) {
  const double pitch = std::atan2(-c(2, 0), std::hypot(c(2, 1), c(2, 2)));
  const double roll = std::atan2(c(2, 1), c(2, 2));
  const double yaw = std::atan2(c(1, 0), c(0, 0));
  return {roll, pitch, yaw};
}

Eigen::Matrix3d dcmFromEuler(const Eigen::Vector3d& rpy) {
  const Eigen::AngleAxisd roll(rpy.x(), Eigen::Vector3d::UnitX());
  const Eigen::AngleAxisd pitch(rpy.y(), Eigen::Vector3d::UnitY());
  const Eigen::AngleAxisd yaw(rpy.z(), Eigen::Vector3d::UnitZ());
  return (yaw * pitch * roll).toRotationMatrix();
}

}  // namespace navbus::core
