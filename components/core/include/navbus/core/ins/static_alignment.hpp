// Static coarse alignment: levelling from the mean specific force and gyrocompassing from the
// mean angular rate of an IMU at rest, with the alignment's own error budget (the initial
// attitude covariance of the fine alignment that follows in the filter).
//
// Method and error analysis: Groves, "Principles of GNSS, Inertial, and Multisensor Integrated
// Navigation Systems", 2nd ed. (2013), section 5.6.2 (self-alignment); Titterton & Weston,
// "Strapdown Inertial Navigation Technology", 2nd ed. (2004), section 10.3. The derivation, with
// the step numbers the code cites, is in static_alignment.cpp.
//
// Frames: body FRD, navigation NED; attitude as roll, pitch, yaw of C_b_n (3-2-1).
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

/// Sums the increments of a stationary window; the means are what the alignment reads.
class StaticWindow {
 public:
  /// Adds one increment (the caller has checked that the vehicle is at rest).
  void add(const ImuIncrement& inc);
  /// Adds another window's increments (a later block of the same rest).
  void add(const StaticWindow& later);
  void reset() { *this = StaticWindow{}; }

  double duration_s() const { return duration_s_; }
  std::uint64_t count() const { return count_; }
  /// Mean specific force over the window, body [m/s^2]; zero before the first increment.
  Eigen::Vector3d meanSpecificForce_b_mps2() const;
  /// Mean inertial angular rate over the window, body [rad/s]; zero before the first increment.
  Eigen::Vector3d meanRate_ib_b_radps() const;

 private:
  Eigen::Vector3d sum_delta_vel_b_mps_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d sum_delta_angle_b_rad_{Eigen::Vector3d::Zero()};
  double duration_s_{0.0};
  std::uint64_t count_{0};
};

/// The sensor errors the alignment cannot see (it reads them as attitude), 1 sigma, SI.
struct AlignmentErrorBudget {
  double accel_bias_sigma_mps2{0.0};               ///< turn-on accelerometer bias, per axis
  double gyro_bias_sigma_radps{0.0};               ///< turn-on gyro bias, per axis
  double velocity_random_walk_mps_per_sqrts{0.0};  ///< accelerometer white noise density
  double angle_random_walk_rad_per_sqrts{0.0};     ///< gyro white noise density
};

/// Why gyrocompassing gave no heading (kNone: it did).
enum class HeadingLimit : std::uint8_t {
  kNone,
  kGyroGrade,  ///< heading sigma from the budget above the accepted limit (step 7)
  kNearPole,   ///< horizontal Earth rate too small to point north
  kNoData,     ///< the window is empty
};

struct CoarseAlignment {
  Eigen::Quaterniond q_b_to_n{Eigen::Quaterniond::Identity()};  ///< yaw 0 without a heading
  Eigen::Vector3d roll_pitch_yaw_rad{Eigen::Vector3d::Zero()};
  double level_sigma_rad{0.0};    ///< roll and pitch, 1 sigma (step 6)
  double heading_sigma_rad{0.0};  ///< gyrocompassing heading, 1 sigma (step 7), even if refused
  HeadingLimit heading_limit{HeadingLimit::kNone};
  bool hasHeading() const { return heading_limit == HeadingLimit::kNone; }
};

/// Heading 1 sigma that gyrocompassing reaches with this budget after `duration_s` at rest at
/// `latitude_rad` (step 7); +infinity at the poles and for an empty window.
double gyrocompassingHeadingSigma(const AlignmentErrorBudget& budget, double duration_s,
                                  double latitude_rad, double level_sigma_rad);

/// Roll and pitch 1 sigma from the accelerometer budget (step 6); +infinity for an empty window.
double levellingSigma(const AlignmentErrorBudget& budget, double duration_s, double gravity_mps2);

/// Levels and gyrocompasses from the window's means at `latitude_rad`. The heading is kept only
/// when its sigma is at most `max_heading_sigma_rad`; otherwise yaw is 0 and heading_limit says
/// why (the heading must come from elsewhere: a star tracker or the GNSS course).
CoarseAlignment alignStatic(const StaticWindow& window, double latitude_rad, double gravity_mps2,
                            const AlignmentErrorBudget& budget, double max_heading_sigma_rad);

/// First-order sensitivity of the alignment's attitude error phi (NED) to the true sensor
/// biases (body), step 8: phi = d_att_d_accel_bias_b b_a + d_att_d_gyro_bias_b b_g (+ noise).
/// A filter started from the alignment needs these correlations: at rest it observes only
/// combinations of attitude and bias errors that the alignment has already made zero.
struct AlignmentSensitivity {
  Eigen::Matrix3d d_att_d_accel_bias_b{Eigen::Matrix3d::Zero()};  ///< [rad / (m/s^2)]
  Eigen::Matrix3d d_att_d_gyro_bias_b{Eigen::Matrix3d::Zero()};   ///< [rad / (rad/s)]
};

/// Step 8 for the aligned attitude C_b_n. `heading_from_gyros`: the heading came from
/// gyrocompassing (otherwise only the levelling rows are filled).
AlignmentSensitivity alignmentSensitivity(const Eigen::Matrix3d& C_b_n, double latitude_rad,
                                          double gravity_mps2, bool heading_from_gyros);

/// Step 9: the part of the Earth-rate mismatch under a heading error psi (phi = (0, 0, psi),
/// C_b_n computed = exp(-[phi x]) C_b_n true) that the first-order error model leaves out, in
/// the computed NED frame, and its derivative with respect to psi. A filter at rest learns it
/// as a gyro bias; once the heading is measured it is known and can be taken out.
struct EarthRateMismatch {
  Eigen::Vector3d remainder_radps{Eigen::Vector3d::Zero()};    ///< [rad/s] NED
  Eigen::Vector3d d_remainder_d_psi{Eigen::Vector3d::Zero()};  ///< [rad/s / rad] NED
};
EarthRateMismatch earthRateMismatchRemainder(double psi_rad, const Eigen::Vector3d& w_ie_ned_radps);
/// Step 10: the variance of step 9's north term while psi is unknown, psi ~ N(0, var_psi_rad2)
/// [(rad/s)^2]: what a filter at rest cannot tell from its computed-north gyro bias.
double earthRateRemainderNorthVariance(double var_psi_rad2, const Eigen::Vector3d& w_ie_ned_radps);

}  // namespace navbus::core
