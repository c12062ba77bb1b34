// Initial alignment from what the bus offers, chosen automatically: the state and covariance a
// navigation filter starts from when nobody configured them.
//
// Position, velocity (and the receiver clock) come from the first GNSS fix, or from a
// least-squares solution of the first pseudorange epoch. Attitude, by priority:
//  1. a star tracker: its body -> ECI attitude rotated into NED at the fix position;
//  2. static coarse alignment (static_alignment.hpp) over a window at rest: levelling, and
//     gyrocompassing when the gyro grade allows a heading sigma within the configured limit;
//  3. otherwise levelled at rest, the attitude carried on with the gyros, and the heading taken
//     from the GNSS course (body x along the horizontal velocity) once the vehicle moves faster
//     than a configured speed.
// The start's sigmas are the alignment's own error budget. Pure math: inputs in processing
// order, no clock, no I/O.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navbus/core/filter/aiding_inputs.hpp"
#include "navbus/core/gnss/gnss_measurement.hpp"
#include "navbus/core/filter/multi_dimensional.hpp"
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

/// One pseudorange epoch's least-squares position and velocity as a fix, with the receiver
/// clock. Equal weights: each sigma is its DOP times the satellites' RMS sigma, each horizontal
/// axis the whole HDOP (an upper bound). valid false: fewer than 4 usable satellites or no
/// convergence.
struct PseudorangeFix {
  bool valid{false};
  GnssFixMeasurement fix;
  double clock_bias_m{0.0}, clock_drift_mps{0.0};
  double clock_bias_sigma_m{0.0}, clock_drift_sigma_mps{0.0};
};
PseudorangeFix pseudorangeFix(std::int64_t time_ns, const std::vector<SatelliteObservation>& sats,
                              const Eigen::Vector3d& guess_ecef_m);

class InitialAligner {
 public:
  explicit InitialAligner(const InitialAlignmentConfig& config);

  void addImu(const ImuIncrement& inc);
  /// One epoch of corrected pseudoranges and rates (satellite positions in ECEF at reception).
  void addPseudoranges(std::int64_t time_ns, const std::vector<SatelliteObservation>& sats);
  void addGnssFix(const GnssFixMeasurement& fix);
  void addStarAttitude(const StarAttitudeMeasurement& st);

  AlignmentPhase phase() const { return phase_; }
  bool aligned() const { return phase_ == AlignmentPhase::kAligned; }
  /// Valid once aligned().
  const AlignedStart& start() const { return start_; }
  /// Pseudorange epochs whose least-squares solution failed (fewer than 4 satellites or no
  /// convergence).
  std::uint64_t failedSolutions() const { return failed_solutions_; }

 private:
  struct Fix {
    std::int64_t time_ns{-1};
    GnssFixMeasurement measurement;
    PositionSource source{PositionSource::kNone};
    double clock_bias_m{0.0}, clock_drift_mps{0.0};
    double clock_bias_sigma_m{0.0}, clock_drift_sigma_mps{0.0};
  };

  void takeFix(const Fix& fix);
  void onMotion();
  void onRestWindowEnd();
  CoarseAlignment alignWindow(double max_heading_sigma_rad) const;
  void relevel();
  void propagateAttitude(const ImuIncrement& inc);
  void tryCourse();
  void finish(const Eigen::Quaterniond& q_b_to_n, const Eigen::Vector3d& att_sigma_ned_rad,
              AttitudeSource source, const AlignmentSensitivity& sensitivity = {});
  double gravity() const;
  bool hasFix() const { return fix_.time_ns >= 0; }

  InitialAlignmentConfig config_;
  AlignmentPhase phase_{AlignmentPhase::kWaitingForPosition};
  Fix fix_;
  StationarityDetector rest_;
  StaticWindow window_;  ///< the increments known to be at rest
  StaticWindow recent_;  ///< the block before the newest: committed once the newest is at rest
  StaticWindow newest_;  ///< the block being filled (one detector window long)
  std::int64_t last_imu_ns_{-1};
  // Levelled, waiting for the course: yaw 0 at the first levelling, then carried by the gyros;
  // roll and pitch levelled again while at rest.
  Eigen::Quaterniond q_levelled_b_to_n_{Eigen::Quaterniond::Identity()};
  /// The attitude at the latest levelling (yaw as carried then): its tilt errors are the ones
  /// the accelerometer biases made (step 8 once the course gives the heading).
  Eigen::Quaterniond q_at_levelling_b_to_n_{Eigen::Quaterniond::Identity()};
  double level_sigma_rad_{0.0};
  double levelled_for_s_{0.0};
  double gyrocompass_sigma_rad_{0.0};
  std::uint64_t failed_solutions_{0};
  AlignedStart start_;
};

}  // namespace navbus::core
