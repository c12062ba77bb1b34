// The integrated navigation filter: strapdown mechanization with error-state feedback and the
// fusion structures of seed 001 over the state layout of state_layout.hpp.
//  - centralized: one error-state EKF takes every measurement (seed 001 eqs. 22-23 in
//    sequential Joseph form);
//  - federated, no-reset mode: a GNSS/INS and a star-tracker/INS local filter, each with its own
//    covariance, fused by the master (eqs. 28-29) after every local update; the master estimate
//    is fed back into the shared mechanization and subtracted from both local estimates, whose
//    covariances are never reset;
//  - adaptive: the centralized filter with R of the aiding measurements re-estimated from a
//    window of innovations (eqs. 30-34).
// Attitude errors are phi angles in NED (computed C_b_n = (I - [phi x]) C_b_n,true), see
// state_layout.hpp; all errors are estimate minus truth.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Cholesky>

#include "navbus/core/filter/aiding_inputs.hpp"
#include "navbus/core/filter/aiding_measurements.hpp"
#include "navbus/core/filter/epoch_diagnostics.hpp"
#include "navbus/core/filter/error_state.hpp"
#include "navbus/core/filter/filter_tuning.hpp"
#include "navbus/core/filter/innovation_window.hpp"
#include "navbus/core/filter/propagation_interval.hpp"
#include "navbus/core/filter/pseudorange_error_slots.hpp"
#include "navbus/core/filter/rts_smoother.hpp"
#include "navbus/core/gnss/gnss_measurement.hpp"
#include "navbus/core/ins/imu_correction.hpp"
#include "navbus/core/ins/ins_error_model.hpp"
#include "navbus/core/math/kalman_update.hpp"
#include "navbus/core/math/scratch.hpp"

namespace navbus::core {

/// What an aiding measurement is: selects the local filter (federated) and the innovation
/// window (adaptive).
enum class AidingKind { kPosition, kVelocity, kAttitude, kZeroVelocity, kNonHolonomic };

struct MeasurementReport {
  int sv_id;
  bool rate;   ///< false: pseudorange row, true: pseudorange-rate row
  bool fused;  ///< offered to the update (false: excluded, monitored only)
  ScalarUpdateResult result;
};

class IntegratedFilter {
 public:
  /// Number of leading states the federated master fuses: all but the receiver's (clock and
  /// pseudorange errors), which only the GNSS local filter observes.
  static constexpr int kFusedStates = layout::kClockBias.index;
  static_assert(layout::kClockDrift.end() == layout::kPseudorangeError.index &&
                    layout::kPseudorangeError.end() == layout::kSize,
                "the receiver's states must trail the layout");

  /// Starts from `state` with the tuning's initial sigmas (initialSigma).
  void initialize(const NavState& state, double clock_bias_m, double clock_drift_mps,
                  const FilterTuning& tuning, const StateMask& active,
                  FusionStructure structure = FusionStructure::kCentralized);
  /// Starts from `state` with an explicit initial covariance (an alignment's own budget, with
  /// its attitude-bias correlations), in the units of the state layout.
  void initialize(const NavState& state, double clock_bias_m, double clock_drift_mps,
                  const FilterTuning& tuning, const StateMask& active, FusionStructure structure,
                  const StateMatrix& initial_covariance);
  /// The tuning's initial 1-sigma of every state (the configured start).
  static StateVector initialSigma(const FilterTuning& tuning);
  /// Mechanizes one increment (compensated for the biases and scale factors) and propagates the
  /// clock and, unless `suspend_filter` (the filter is not run: seed 004's case I during an
  /// outage), the covariance(s).
  void propagate(const ImuIncrement& raw, bool suspend_filter = false);
  /// Applies the covariance propagation the increments since the last one gathered
  /// (FilterTuning::covariance_period_s; nothing when none is pending). Every method that
  /// reads or changes the covariance in here does it first; a caller that reads covariance(),
  /// local(), transitionSinceUpdate() or processNoisePart() between increments calls it
  /// before (the engine does at each solution epoch and measurement).
  void settleCovariance();
  /// Whether increments wait for their covariance propagation.
  bool covariancePending() const { return !pending_.empty(); }
  /// Processes one epoch of pseudoranges and rates; returns one report per row (a buffer
  /// reused from epoch to epoch, valid until the next call). Rows a satellite's use_range /
  /// use_rate exclude are monitored only: their innovations are in the diagnostics (for the
  /// fault monitor's readmission test) but they do not update the filter.
  /// The ranges are predicted at the antenna, `antenna` away from the IMU.
  const std::vector<MeasurementReport>& update(const std::vector<SatelliteObservation>& sats,
                                               const AntennaArm& antenna = {});
  /// The same for the stacked epoch of several receivers: each satellite's rows take the clock
  /// states and the antenna of its receiver (SatelliteObservation::receiver).
  const std::vector<MeasurementReport>& update(const std::vector<SatelliteObservation>& sats,
                                               const AntennaArms& antennas);
  /// Processes an aiding measurement, one decorrelated row at a time.
  template <int M>
  std::array<ScalarUpdateResult, M> update(const AidingMeasurement<M>& m, AidingKind kind);

  /// Switches the fusion structure at run time (the estimate carries over; see .cpp).
  void setStructure(FusionStructure s);
  FusionStructure structure() const { return structure_; }

  /// Covariance management for the multi-dimensional filter (seed 004).
  void setActive(const StateMask& active);
  /// Which states the updates correct; the others are consider states (error_state.hpp).
  void setEstimated(const StateMask& estimated);
  void zeroOffDiagonal();
  void resetVariances(const StateBlock& block, double sigma);
  /// Raises each variance of the block to at least sigma^2, correlations kept (adding a
  /// nonnegative diagonal keeps P positive definite).
  void inflateVariances(const StateBlock& block, double sigma);
  /// Adds `variance` to one state's variance (a correction of uncertain size was applied).
  void addVariance(int state, double variance);
  /// Re-initialisation from an independent GNSS solution: position and velocity are set to
  /// the fix and their covariance rows replaced by its variances (no correlation with the
  /// rest: what the filter knew of them no longer holds). Attitude, biases and clock keep
  /// theirs.
  void resetNavigation(const GnssFixMeasurement& fix);
  /// The same for a receiver's clock (bias [m], drift [m/s] and their sigmas; receiver 0 the
  /// first fused one).
  void resetClock(double bias_m, double drift_mps, double bias_sigma_m, double drift_sigma_mps,
                  int receiver = 0);
  /// The GNSS course against the INS course (NavigationEngine::checkHeadingFromCourse):
  ///   z = course_gnss - course_ins = -u_c . e_v / speed + noise,
  /// u_c the unit vector across the track: the cross-track velocity error, which the velocity
  /// gained from rest through a heading error phi_D makes -phi_D speed (the covariance carries
  /// that correlation). The covariance takes the linear update; the heading and the horizontal
  /// velocity take theirs as an exact rotation about the vertical (the INS velocity gained
  /// through the heading error is the true one rotated by it: the first-order correction would
  /// leave (1 - cos phi_D) of the speed along the track, 3.6 % at 0.27 rad), the other states
  /// the linear one. Centralized and adaptive structures only (false: federated).
  bool correctHeadingFromCourse(double z_rad, double sigma_rad, double course_rad,
                                double speed_mps);
  /// While the heading sigma is large (before the course check): a filter at rest measures the
  /// computed-north gyro bias together with the Earth rate's second-order remainder
  /// W cos L (cos psi - 1) (static_alignment.cpp step 9), unknown while psi is. Keeps the
  /// variance of that gyro-bias direction at least the remainder's (step 10), so the filter
  /// does not claim it knows more. Centralized and adaptive structures (as the course check).
  void floorEarthRateRemainderVariance();
  /// At rest before the course check: keeps the heading variance at least the gyrocompass's
  /// along the direction that changes the heading and the east gyro bias together (one
  /// observable at rest). Centralized and adaptive structures.
  void floorGyrocompassHeadingVariance(double heading_sigma_rad);
  /// Marks an IMU axis failed (or trusted again): while failed, its bias state is a random
  /// walk of the tuning's failed_* density, so the aiding carries that axis.
  void setAxisFailed(bool accelerometer, int axis, bool failed);
  const StateMask& active() const { return central_.active(); }
  const StateMask& estimated() const { return central_.estimated(); }
  /// The transition accumulated since the last update of any kind (the GLR's Phi between two
  /// epochs that no other update separates).
  StateMatrix transitionSinceUpdate() const { return phi_since_update_t_.transpose(); }

  const NavState& state() const { return ins_.state(); }
  /// The covariance of the estimate: the centralized one, or the master's (federated).
  const StateMatrix& covariance() const { return central_.P(); }
  const ErrorState& local(int i) const { return local_[static_cast<std::size_t>(i)]; }
  const Eigen::Vector3d& accelBias() const { return accel_bias_; }
  const Eigen::Vector3d& gyroBias() const { return gyro_bias_; }
  /// Estimated scale-factor errors [1, body] (0 while not modelled).
  const Eigen::Vector3d& accelScale() const { return accel_scale_; }
  const Eigen::Vector3d& gyroScale() const { return gyro_scale_; }
  /// What propagate() removes from each increment.
  ImuCorrection imuCorrection() const {
    return {accel_bias_, gyro_bias_, accel_scale_, gyro_scale_};
  }
  /// The star tracker's estimated bias [rad, star-tracker axes], subtracted from its
  /// measurements (attitudeMeasurement()); 0 while the bias is not modelled.
  const Eigen::Vector3d& starTrackerBias() const { return star_tracker_bias_; }
  /// The estimated residual mounting misalignment [rad, body; layout::kMountingMisalignment]
  /// while it is modelled (zero otherwise): the block's estimate, which a star tracker's bias
  /// shares when there is one.
  Eigen::Vector3d mountingMisalignment() const {
    return modelsMountingMisalignment() ? star_tracker_bias_ : Eigen::Vector3d::Zero();
  }
  /// The mounting misalignment is a state (tuning sigma positive, block active).
  bool modelsMountingMisalignment() const;
  /// Estimated error of the GNSS fix's position [m, NED] (zero when not modelled).
  const Eigen::Vector3d& fixPositionError() const { return fix_position_error_ned_m_; }
  /// The fix's position error is a state (tuning sigma positive, block active, no pseudorange
  /// errors sharing the block).
  bool modelsFixPositionError() const;
  /// A fused receiver's clock bias c*b [m] and drift c*f [m/s] (receiver 0: the first).
  double clockBias(int receiver = 0) const { return clock_bias_m_[slot(receiver)]; }
  double clockDrift(int receiver = 0) const { return clock_drift_mps_[slot(receiver)]; }
  /// A receiver's clock jumped by `jump_m` (c times the step [m]), known to `sigma_m`: the
  /// clock bias moves with it and its variance grows by sigma_m^2.
  void shiftClock(double jump_m, double sigma_m, int receiver = 0);
  /// A second fused receiver's clock is modelled (layout::kSecondClockBias: the last two
  /// pseudorange-error states, left to it); call after initialize().
  void modelSecondReceiverClock(bool on);
  /// The satellites' time-correlated pseudorange errors (tight coupling, when modelled).
  const PseudorangeErrorSlots& pseudorangeErrors() const { return pseudorange_errors_; }
  /// Whether the transition since the last update is kept for the pseudorange epochs'
  /// diagnostics (the GLR's Phi): on for tightly coupled aiding, off otherwise (it costs a third
  /// of the covariance propagation).
  void keepTransitionSinceUpdate(bool on) {
    settleCovariance();
    keep_transition_ = on;
  }
  /// Adaptive process noise (adaptive_process_noise.hpp): the scale on the inertial process
  /// noise (velocity and attitude white noise, IMU bias random walks) from the next increment on.
  void setProcessNoiseScale(double scale) { process_noise_scale_ = scale; }
  /// Keeps the part of P that the inertial process noise added since forgetProcessNoise() (off
  /// by default: it costs a second covariance propagation). Centralized structures.
  void trackProcessNoise(bool on);
  /// That part (zero unless tracked; ErrorState::processNoisePart), and its restart.
  StateMatrix processNoisePart() const { return central_.processNoisePart(); }
  void forgetProcessNoise() {
    settleCovariance();
    central_.forgetProcessNoise();
  }
  const EpochDiagnostics& lastEpoch() const { return *last_epoch_; }
  void restartAt(std::int64_t time_ns) {
    settleCovariance();
    ins_.restartAt(time_ns);
  }
  /// Records what a fixed-interval smoother needs into `log` (nullptr: nothing recorded, the
  /// default), from the next increment on (rts_smoother.hpp). Not owned.
  void setSmoothingLog(SmoothingLog* log) { smoothing_log_ = log; }
  /// Records the epoch still pending (the updates since the last increment): the end of a run.
  void closeSmoothingRecord();
  bool initialized() const { return ins_.initialized(); }
  const FilterTuning& tuning() const { return tuning_; }

 private:
  /// The error state a measurement goes to.
  ErrorState& target(AidingKind kind);
  /// Applies the estimate after an update: centralized feedback, or master fusion + feedback.
  void closeUpdate();
  void resetState(int i, double sigma);
  void feedback(const StateVector& dx);
  /// P's attitude rows and columns through the reset of a heading correction (before
  /// feedback): turned by R_D(dpsi) with the frame the INS computes.
  void turnAttitudeCovariance(double dpsi_rad);
  /// Whether the satellites' pseudorange errors are states (layout::kPseudorangeError active).
  bool modelsPseudorangeErrors() const;
  /// Whether the star tracker's bias is a Gauss-Markov state (not a mounting misalignment).
  bool modelsStarTrackerBias() const;
  /// One increment's discrete process noise, the Gauss-Markov states' left out.
  StateVector processNoise(double dt) const;
  /// The Gauss-Markov states' estimates over one increment (their expected value decays).
  void decayGaussMarkovEstimates(double dt);
  /// The Gauss-Markov states' transition (exp(-T / tau)) and driving noise over T.
  void gaussMarkovTransition(double T, StateMatrix& Phi, StateVector& q) const;
  /// Gives this epoch's satellites their pseudorange-error states (a new one starts from the
  /// prior); returns each satellite's state index, -1 where none is modelled.
  const std::vector<int>& pseudorangeErrorStates(const std::vector<SatelliteObservation>& sats);
  InnovationWindow<3>* window(AidingKind kind);
  /// Smoothing log: the record of the epoch reached (at an increment's start, when the epoch
  /// had updates or the log's interval has passed).
  void recordForSmoothing();
  void emitSmoothingRecord();
  /// Covariance jumps: every change of P outside propagation and updates goes between
  /// beginCovarianceJump() and endCovarianceJump(), so that the smoother's model has it (the
  /// updates already taken at the epoch get their record first; the predicted covariance of
  /// the next record includes the jump; a replaced state zeroes its row of the transition).
  /// A reset no process noise gives breaks the smoothing instead (rts_smoother.hpp).
  void beginCovarianceJump();
  void endCovarianceJump(int replaced_state = -1);
  void breakSmoothing();

  FilterTuning tuning_;
  std::array<bool, 6> axis_failed_{};  ///< accelerometers x y z, gyros x y z
  FusionStructure structure_{FusionStructure::kCentralized};
  StrapdownNed ins_;
  ErrorState central_;               ///< centralized/adaptive filter; master result (federated)
  std::array<ErrorState, 2> local_;  ///< federated: [0] GNSS/INS, [1] star tracker/INS
  std::array<InnovationWindow<3>, 3> windows_;  ///< adaptive: position, velocity, attitude
  /// The transition accumulated since the last update, transposed (the product's cheap form,
  /// SparseRows::timesTransposedBlockTriangular).
  StateMatrix phi_since_update_t_{StateMatrix::Identity()};
  bool keep_transition_{true};
  PropagationInterval pending_;      ///< increments whose covariance propagation waits
  double process_noise_scale_{1.0};  ///< on the inertial process noise (setProcessNoiseScale)
  // The latest epoch's outputs and the update's working buffers: each update rewrites them
  // before it reads them, so the recovery history's copies of the filter leave them out
  // (Scratch: an engine snapshot copies no epoch's diagnostics, a restore keeps the buffers).
  Scratch<EpochDiagnostics> last_epoch_;
  Scratch<AppliedGain> applied_gain_;  ///< the diagnostics' K from the sequential updates
  Scratch<std::vector<MeasurementReport>> reports_;
  Scratch<Eigen::VectorXd> range_variances_;   ///< R's diagonal of the epoch being processed
  Scratch<std::vector<int>> epoch_sv_ids_;     ///< the satellites of the epoch being processed
  Scratch<std::vector<int>> no_error_states_;  ///< -1 per satellite: errors not modelled
  Eigen::Vector3d accel_bias_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d gyro_bias_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d accel_scale_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d gyro_scale_{Eigen::Vector3d::Zero()};
  /// The star tracker's bias, or a land vehicle's mounting misalignment (the block's estimate).
  Eigen::Vector3d star_tracker_bias_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d fix_position_error_ned_m_{Eigen::Vector3d::Zero()};
  static std::size_t slot(int receiver) { return static_cast<std::size_t>(receiver); }
  /// Each fused receiver's clock (layout::clockBiasOf / clockDriftOf its states).
  std::array<double, layout::kMaxFusedReceivers> clock_bias_m_{};
  std::array<double, layout::kMaxFusedReceivers> clock_drift_mps_{};
  bool second_clock_{false};  ///< modelSecondReceiverClock
  PseudorangeErrorSlots pseudorange_errors_;
  /// What the next smoothing record gathers since the last one.
  struct SmoothingPending {
    StateMatrix transition_t{StateMatrix::Identity()};  ///< since the last record, transposed
    StateMatrix predicted{StateMatrix::Zero()};
    StateVector correction{StateVector::Zero()};
    bool predicted_taken{false};
    bool updated{false};
    bool continues{false};  ///< false: no smoothing across the previous record
    bool starts_run{true};  ///< the first record of a run is due
    std::int64_t last_record_ns{-1};
    std::int64_t records_kept{-1};  ///< the log's size after the last record (-1: none yet)
  };
  SmoothingLog* smoothing_log_{nullptr};
  SmoothingPending smoothing_;
};

template <int M>
std::array<ScalarUpdateResult, M> IntegratedFilter::update(const AidingMeasurement<M>& m,
                                                           AidingKind kind) {
  settleCovariance();
  AidingMeasurement<M> used = m;
  ErrorState& es = target(kind);
  if constexpr (M == 3) {
    if (InnovationWindow<3>* w = window(kind)) {
      // Eq. 30: dz = z - H x-; eqs. 31-34 with this epoch's H P- H^T.
      const Eigen::Vector3d dz = m.z - m.h * es.x();
      const Eigen::Matrix3d hpht = m.h * es.P() * m.h.transpose();
      w->push(dz);
      if (w->full())
        used.r = w->adaptedR(hpht, tuning_.adaptive_floor_at_reported ? &m.r : nullptr);
    }
  }
  const std::array<ScalarUpdateResult, M> out = es.update(used, tuning_.gate_sigma);
  closeUpdate();
  return out;
}

}  // namespace navbus::core
