// `navbus calibrate mounting`: the residual rotation between the body axes the filter works in
// (the IMU's axes turned by geometry.imu_mounting_rpy_deg) and the vehicle's own axes, which
// the non-holonomic constraint assumes: a car moves along its forward axis, with no sideways
// and no vertical velocity in its own frame. A residual pitch or yaw of the mounting makes the
// constraint report a velocity of speed times that angle as an error of the navigation
// solution (0.9 deg at 16 m/s: 0.25 m/s, more than the constraint's usual sigma).
// The procedure, repeatable on any vehicle's log: the filter runs over the whole log with GNSS
// never withheld and the fixed-interval smoother behind it; at every smoothed epoch driven
// straight (speed above a bound, the course's rate of change below one: no sideslip), the direction
// of the velocity in body axes, v_b = C_n_b v_n, gives the pitch and yaw of the vehicle's forward
// axis in body axes. Their medians are the residual; the corrected mounting angles are
// printed for the configuration. The sideways and vertical velocity left in the vehicle's axes
// over every epoch above the speed bound (turns included) is what the constraint must allow:
// their RMS, before and after the correction, are the evidence for its sigma. Roll is not
// observable this way (a rotation about the direction of travel leaves v_b unchanged).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navbus/core/filter/rts_smoother.hpp"
#include "navbus/core/math/units.hpp"
#include "navbus/evaluation/recording_runner.hpp"

namespace navbus::evaluation {

struct StraightDriving {
  double min_speed_mps{5.0};
  double max_heading_rate_radps{2.0 * units::kDeg};
};

struct MountingResidual {
  std::size_t epochs{0};  ///< straight-driving epochs used
  double pitch_rad{0.0};  ///< median pitch of the velocity in body axes (up positive)
  double yaw_rad{0.0};    ///< median yaw of the velocity in body axes (right positive)
  double pitch_q1_rad{0.0}, pitch_q3_rad{0.0};  ///< quartiles
  double yaw_q1_rad{0.0}, yaw_q3_rad{0.0};
  /// Over every smoothed epoch above the speed bound: the velocity across and below the
  /// forward axis [m/s], RMS, in the body axes as configured and turned by the residual.
  std::size_t moving_epochs{0};
  Eigen::Vector2d configured_rms_mps{Eigen::Vector2d::Zero()};  ///< lateral, vertical
  Eigen::Vector2d corrected_rms_mps{Eigen::Vector2d::Zero()};
  /// Over the straight epochs: the least-squares slope of the velocity's pitch in body axes
  /// against the longitudinal acceleration (the speed's change over +-0.5 s) [rad per m/s^2],
  /// with its correlation coefficient; a car's body pitches against its track as it speeds up
  /// or brakes.
  double velocity_pitch_per_accel_rad_per_mps2{0.0};
  double velocity_pitch_accel_correlation{0.0};
};

/// The residual from smoothed epochs (only those with `smoothed` true count).
MountingResidual mountingResidual(const std::vector<core::SmoothedEpoch>& epochs,
                                  const StraightDriving& straight);

/// The mounting angles (RTKLIB-style IMU-to-body roll, pitch, yaw [rad], as
/// core::ImuMounting::fromRollPitchYaw takes them) after turning the body axes by the residual,
/// so that the vehicle's forward axis becomes the body's x axis.
Eigen::Vector3d correctedMountingRpy(const Eigen::Matrix3d& sensor_to_body,
                                     const MountingResidual& residual);

struct MountingOptions {
  std::string dataset;
  std::string filter;
  std::string out_dir;  ///< the imported recording
  StraightDriving straight;
};

/// The run the calibration reads: smoothed, GNSS never withheld, and the filter's model held
/// fixed (a consistency alarm does not raise the IMU bias sigmas: on the clean drive its one
/// alarm, so answered, took the corrected sideways RMS from 0.095 to 0.128 m/s).
void configureMountingRun(RecordingSetup& setup);

int runMountingCommand(const MountingOptions& o);

}  // namespace navbus::evaluation
