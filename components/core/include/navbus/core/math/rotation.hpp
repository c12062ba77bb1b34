// Rotation helpers: rotation vectors, quaternions, Euler angles (3-2-1, NED/FRD).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace navbus::core {

/// Skew-symmetric matrix with skew(a) * b == a.cross(b).
Eigen::Matrix3d skew(const Eigen::Vector3d& a);

/// Quaternion of the rotation by |phi| about phi/|phi| (exact, series near zero).
Eigen::Quaterniond quaternionFromRotationVector(const Eigen::Vector3d& phi_rad);

/// Roll, pitch, yaw (3-2-1 sequence) of C_b_n; pitch in [-pi/2, pi/2].
Eigen::Vector3d eulerFromDcm(const Eigen::Matrix3d& C_b_n);

/// C_b_n from roll, pitch, yaw (3-2-1 sequence).
Eigen::Matrix3d dcmFromEuler(const Eigen::Vector3d& roll_pitch_yaw_rad);

}  // namespace navbus::core
