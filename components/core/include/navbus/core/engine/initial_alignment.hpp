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

#include <array>
#include <optional>

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navbus/core/engine/alignment_config.hpp"
#include "navbus/core/filter/aiding_inputs.hpp"
#include "navbus/core/filter/multi_dimensional.hpp"
#include "navbus/core/gnss/gnss_measurement.hpp"
#include "navbus/core/ins/static_alignment.hpp"
#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

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
  /// The tilt 1-sigma of the levelled attitude now.
  double currentLevelSigma() const;
  /// A heading from the GNSS course: the course, the levelled attitude's yaw at the course's
  /// time, and the heading's 1-sigma.
  struct Course {
    double course_rad{0.0};
    double yaw_rad{0.0};
    double heading_sigma_rad{0.0};
    /// From two fixes: the velocity at the newer one and its 1-sigma [m/s, NED], which the
    /// filter starts from when the fix's own velocity is worse.
    std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> velocity_ned_mps;
  };
  void tryCourse();
  std::optional<Course> courseFromVelocity() const;
  std::optional<Course> courseFromPositions() const;
  struct TrackPoint;
  std::pair<Eigen::Vector3d, Eigen::Vector3d> chordVelocity(const TrackPoint& now,
                                                            const TrackPoint& then,
                                                            double heading_correction_rad) const;
  /// The fixes taken while waiting for the course, with the levelled yaw at each (a ring).
  struct TrackPoint {
    std::int64_t time_ns{0};
    earth::Geodetic position;
    double sigma_h_m{0.0};  ///< the larger horizontal 1-sigma
    double yaw_rad{0.0};
    /// The horizontal velocity change the levelled attitude integrated up to this point
    /// [m/s, north and east of the levelled frame, whose yaw is off by the unknown heading].
    Eigen::Vector2d levelled_dv_ne_mps{Eigen::Vector2d::Zero()};
  };
  static constexpr std::size_t kTrackPoints = 128;  ///< 32 s of 4 Hz fixes
  void finish(const Eigen::Quaterniond& q_b_to_n, const Eigen::Vector3d& att_sigma_ned_rad,
              AttitudeSource source, const AlignmentSensitivity& sensitivity = {});
  /// The velocity change integrated while waiting for the course (TrackPoint).
  Eigen::Vector2d levelled_dv_ne_mps_{Eigen::Vector2d::Zero()};
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
  std::array<TrackPoint, kTrackPoints> track_{};
  std::size_t track_count_{0};  ///< points held (the newest at (track_next_ - 1) mod size)
  std::size_t track_next_{0};
  AlignedStart start_;
};

}  // namespace navbus::core
