// The initial alignment's configuration and result (initial_alignment.hpp): what it waits
// for, where the attitude and position came from, and the start with its 1-sigma budget.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "navbus/core/filter/mdf_config.hpp"
#include "navbus/core/ins/static_alignment.hpp"
#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

enum class AttitudeSource : std::uint8_t { kNone, kStarTracker, kGyrocompass, kGnssCourse };
enum class PositionSource : std::uint8_t { kNone, kGnssFix, kPseudoranges };

/// Where the alignment stands (what it waits for).
enum class AlignmentPhase : std::uint8_t {
  kWaitingForPosition,  ///< no GNSS fix or pseudorange solution yet
  kWaitingForRest,      ///< no attitude source yet: collecting a window at rest
  kWaitingForCourse,    ///< levelled; heading from the GNSS course once moving
  kAligned
};

struct InitialAlignmentConfig {
  AlignmentErrorBudget budget;           ///< the IMU's turn-on biases and noise densities
  StationarityConfig rest;               ///< what counts as at rest (scatter and GNSS speed)
  double static_window_s{60.0};          ///< levelling / gyrocompassing window at rest
  double min_static_window_s{5.0};       ///< a shorter window cut by motion is discarded
  double max_heading_sigma_rad{0.1745};  ///< gyrocompassing accepted below (10 deg)
  double course_min_speed_mps{5.0};      ///< GNSS course used above this horizontal speed
  double course_sigma_rad{0.0349};       ///< body x to velocity misalignment, 1 sigma (2 deg)
  /// The alignment ends on a course only once its heading 1-sigma is below this: beyond it the
  /// filter's small-angle error model does not hold (a position-only receiver's "velocity"
  /// gave 2.8 rad).
  double max_course_heading_sigma_rad{0.1745};
  /// The course is also taken from two fixes up to this far apart in time (receivers that give
  /// positions only, or poor velocities), when the track between them is straight: the gyros
  /// turned it by less than twice course_sigma_rad.
  double course_window_s{10.0};
  /// After gyrocompassing with a heading sigma above this, the heading is measured once more
  /// from the GNSS course when the vehicle first moves faster than course_min_speed_mps
  /// (NavigationEngine; 0: never).
  double course_check_heading_sigma_rad{0.05};
  double imu_period_s{0.01};  ///< nominal increment interval (stationarity window)
};

/// The state a filter starts from, with the alignment's 1-sigma budget.
struct AlignedStart {
  NavState state;  ///< at the end of the last increment seen
  double clock_bias_m{0.0};
  double clock_drift_mps{0.0};
  bool has_clock{false};  ///< from pseudoranges only
  Eigen::Vector3d pos_sigma_ned_m{Eigen::Vector3d::Zero()};
  Eigen::Vector3d vel_sigma_ned_mps{Eigen::Vector3d::Zero()};
  /// Attitude error sigmas about the NED axes: north and east tilt, heading.
  Eigen::Vector3d att_sigma_ned_rad{Eigen::Vector3d::Zero()};
  double clock_bias_sigma_m{0.0};
  double clock_drift_sigma_mps{0.0};
  AttitudeSource attitude_source{AttitudeSource::kNone};
  PositionSource position_source{PositionSource::kNone};
  /// Heading sigma gyrocompassing reaches with this IMU here (static_alignment.cpp step 7),
  /// reported even when another source was used; 0 before a window at rest.
  double gyrocompass_heading_sigma_rad{0.0};
  /// How the attitude error depends on the true sensor biases (static_alignment.cpp step 8):
  /// the filter starts with these correlations. Zero for a star-tracker attitude.
  AlignmentSensitivity sensitivity;
};

}  // namespace navbus::core
