// The navigation engine: the filter policy between inputs in processing order and the
// estimate (KF-GINS style: addImu, addGnss..., state). It decides when the filter starts,
// restarts over inertial gaps, which measurements each aiding mode uses, runs the
// multi-dimensional stage logic, and marks solution epochs. navbus-filter and the offline
// runner call the same engine with the same inputs, which is what makes them bit-identical.
#pragma once

#include <array>
#include <bitset>
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "navbus/core/engine/alignment_config.hpp"
#include "navbus/core/filter/adaptive_noise_scale.hpp"
#include "navbus/core/filter/adaptive_process_noise.hpp"
#include "navbus/core/filter/aiding_inputs.hpp"
#include "navbus/core/filter/epoch_diagnostics.hpp"
#include "navbus/core/filter/filter_tuning.hpp"
#include "navbus/core/filter/mdf_config.hpp"
#include "navbus/core/gnss/gnss_measurement.hpp"
#include "navbus/core/ins/gap_bridge.hpp"
#include "navbus/core/ins/imu_correction.hpp"
#include "navbus/core/ins/ins_error_model.hpp"
#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/ins/velocity_history.hpp"
#include "navbus/core/integrity/consistency_monitor.hpp"
#include "navbus/core/integrity/fix_innovation_log.hpp"
#include "navbus/core/integrity/protection_level_config.hpp"
#include "navbus/core/math/indirect.hpp"
#include "navbus/core/math/scratch.hpp"

namespace navbus::core {

// The engine's parts: their headers are not part of its interface.
class IntegratedFilter;
class SmoothingLog;
class InitialAligner;
class GlrProtectionLevel;
class StationarityDetector;
class StageSelector;
struct StageDecision;
struct ScalarUpdateResult;
struct MeasurementReport;

enum class AidingMode {
  kInertialOnly,     ///< mechanization and covariance propagation, no updates
  kTightlyCoupled,   ///< pseudoranges and rates (seed 000)
  kLooselyCoupled,   ///< GNSS position/velocity fixes (+ star tracker when enabled; seed 001)
  kMultiDimensional  ///< land vehicle: fixes, ZUPT, NHC with the stage logic (seed 004)
};

/// The aiding streams whose measurement noise adapts (adaptive_noise_scale.hpp), each with its
/// own scale on its own R.
enum class NoiseStream : int {
  kFixPosition,
  kFixVelocity,
  kPseudorange,
  kPseudorangeRate,
  kZeroVelocity,
  kNonHolonomic,
  kStarAttitude,
};
inline constexpr int kNoiseStreams = 7;
/// The stream's name in summaries and configuration ("fix_position", ...).
const char* noiseStreamName(NoiseStream s);

enum class EngineMode {
  kInitializing,
  kInertialOnly,
  kInertialLost,
  kTightlyCoupled,
  kLooselyCoupled,
  kMdfF1,
  kMdfF2,
  kMdfF3,
  kMdfF4,
  kAidedAxisFailed,  ///< tightly or loosely coupled with a failed IMU axis
  kAligning,         ///< aligning from the inputs (InitialAligner): no solution yet
  /// The solution is not trustworthy until the next GNSS solution re-initialises position,
  /// velocity (and the clock): after an inertial gap longer than the bridge, or when the
  /// consistency monitor's alarm has lasted (integrity/consistency_monitor.hpp).
  kReinitialising
};

/// Where the filter's start comes from.
enum class StartSource {
  kConfigured,  ///< EngineConfig::initial_state with the tuning's initial sigmas
  kAligned      ///< InitialAligner from the inputs, with the alignment's own sigmas
};

/// Engine status bits (the participant maps them to the solution's fault flags).
enum EngineStatus : std::uint32_t {
  kStatusImuGap = 1u << 0,
  kStatusSatelliteExcluded = 1u << 1,
  kStatusBiasCompensated = 1u << 2,
  kStatusAxisFailed = 1u << 3,
  kStatusInconsistent = 1u << 4,    ///< the consistency monitor's latest window failed its test
  kStatusReinitialising = 1u << 5,  ///< waiting for a GNSS solution to re-initialise from
};

/// Which measurements of a satellite an exclusion concerns (bit mask).
enum class SatelliteScope : std::uint8_t { kRange = 1, kRate = 2, kAll = 3 };

struct EngineConfig {
  AidingMode aiding{AidingMode::kInertialOnly};
  FusionStructure fusion{FusionStructure::kCentralized};
  FilterTuning tuning;
  bool use_star_tracker{false};  ///< loosely coupled: star-tracker attitude updates
  MdfConfig mdf;                 ///< multi-dimensional mode only
  double imu_period_s{0.01};     ///< nominal increment interval (stationarity window)
  StartSource start{StartSource::kConfigured};
  NavState initial_state;            ///< kConfigured; time is taken from the first increment
  InitialAlignmentConfig alignment;  ///< kAligned (budget, rest detection, course)
  double initial_clock_bias_m{0.0};
  double initial_clock_drift_mps{0.0};
  std::int64_t solution_period_ns{100'000'000};
  GapBridgeConfig gap;  ///< propagation across inertial gaps (ins/gap_bridge.hpp)
  /// Protection levels from the GLR's statistics (tightly coupled mode only).
  IntegrityConfig integrity;
  /// The filter's test of its own innovations, and when it re-initialises.
  ConsistencyConfig consistency;
  /// Bounded adaptive measurement noise: one scale per aiding stream (adaptive_noise_scale.hpp),
  /// on the streams set here (bit i: NoiseStream i; default all).
  NoiseScaleConfig adaptive_noise;
  std::bitset<kNoiseStreams> adaptive_noise_streams{(1u << kNoiseStreams) - 1u};
  /// Bounded adaptive process noise: one scale on the inertial Q from the GNSS innovations
  /// (adaptive_process_noise.hpp). Centralized filter only.
  ProcessNoiseScaleConfig adaptive_process_noise;
  /// The GNSS antenna's offset from the IMU [m, body axes]: fixes and pseudoranges are of the
  /// antenna.
  Eigen::Vector3d antenna_lever_arm_b_m{Eigen::Vector3d::Zero()};
  /// GNSS receivers whose pseudoranges are fused, 1 or layout::kMaxFusedReceivers (tightly
  /// coupled): the second has its own clock states (layout::kSecondClockBias, started from its
  /// first epoch) and its own antenna; the first alone serves the alignment, the
  /// re-initialisation and the course check.
  int fused_receivers{1};
  /// The second fused receiver's antenna offset from the IMU [m, body axes].
  Eigen::Vector3d second_antenna_lever_arm_b_m{Eigen::Vector3d::Zero()};
  /// Post-processing: where the filter records what the fixed-interval smoother needs
  /// (rts_smoother.hpp); nullptr (the default, and always on the bus): nothing recorded.
  /// Not owned; must outlive every engine made from this configuration.
  SmoothingLog* smoothing_log{nullptr};
  /// Post-processing: where each fused GNSS fix's innovations go (fix_innovation_log.hpp);
  /// nullptr (the default, and always on the bus): nothing recorded. Not owned.
  FixInnovationLog* fix_innovation_log{nullptr};
};

struct EngineCounters {
  std::uint64_t imu_used{0}, imu_gaps{0};
  std::uint64_t gaps_bridged{0};  ///< of imu_gaps: propagated across with held inputs
  std::uint64_t imu_aligning{0};  ///< increments the alignment took before the filter started
  /// Increments refused: interval not positive and finite, or not after the state time (an
  /// embedding application may call the engine without the bus validation).
  std::uint64_t imu_refused{0};
  std::uint64_t gnss_epochs_fused{0}, fixes_fused{0}, star_fused{0};
  std::uint64_t zero_velocity_updates{0}, nonholonomic_updates{0};
  std::uint64_t rows_gated{0};  ///< measurement rows refused by the innovation gate
  std::uint64_t stage_switches{0};
  /// Headings measured again from the GNSS course after gyrocompassing
  /// (InitialAlignmentConfig::course_check_heading_sigma_rad).
  std::uint64_t course_heading_checks{0};
  /// Re-initialisations from a GNSS solution: asked for (a gap beyond the bridge, a lasting
  /// inconsistency) and done.
  std::uint64_t reinitialisations_asked{0}, reinitialisations_done{0};
  /// Alarms at which the IMU bias sigmas were raised (ConsistencyConfig::
  /// inflate_imu_biases_on_alarm).
  std::uint64_t bias_inflations{0};
  /// The fixes' position and velocity rows: normalized innovations squared (mean about 1 when
  /// the covariance explains them; navbus calibrate time-offset minimizes them).
  InnovationStatistics fix_position_nis, fix_velocity_nis;
  /// Fix velocities older than the velocity history reaches (compared as they are).
  std::uint64_t fix_velocities_beyond_history{0};
  /// Satellites beyond the kMaxEpochSatellites an epoch (all receivers' together) can hold:
  /// left out of it.
  std::uint64_t epoch_satellites_dropped{0};
  /// Further receivers' clocks started from their first epoch (that epoch is not fused).
  std::uint64_t receiver_clocks_started{0};
};

class NavigationEngine {
 public:
  explicit NavigationEngine(const EngineConfig& config);
  NavigationEngine(const NavigationEngine& other);
  NavigationEngine(NavigationEngine&& other) noexcept;
  /// Copies into this engine's storage (the rollback history's snapshots allocate nothing once
  /// they hold an engine).
  NavigationEngine& operator=(const NavigationEngine& other);
  NavigationEngine& operator=(NavigationEngine&& other) noexcept;
  ~NavigationEngine();

  /// Integrates one increment; true when the state time reached a solution epoch. An increment
  /// with a bad interval or one that does not follow the state time is refused and counted.
  bool addImu(const ImuIncrement& inc);
  /// Fuses a pseudorange epoch of time `time_ns` (tightly coupled mode); true when fused
  /// (diagnostics ready). While aligning, the epoch goes to the aligner.
  bool addGnssEpoch(std::int64_t time_ns, const std::vector<SatelliteObservation>& satellites);
  /// Several fused receivers (EngineConfig::fused_receivers): receiver `receiver`'s epoch of
  /// `time_ns` is held until the caller fuses the held epochs as one (fuseHeldEpoch): once
  /// every fused receiver's epoch of that time is in (heldEpochComplete), or before any input
  /// that is not one of them. Returns false (nothing held) when an epoch of another time or
  /// of the same receiver is held: fuse that first.
  bool holdGnssEpoch(std::int64_t time_ns, const std::vector<SatelliteObservation>& satellites,
                     int receiver);
  bool heldEpochComplete() const;
  /// Whether an epoch is held, and whether `receiver`'s epoch of `time_ns` would join it.
  bool hasHeldEpoch() const { return held_.receivers != 0; }
  std::int64_t heldEpochTime() const { return held_.time_ns; }
  bool joinsHeldEpoch(std::int64_t time_ns, int receiver) const;
  /// Fuses the held epochs as one stacked epoch (addGnssEpoch); false when nothing was fused.
  bool fuseHeldEpoch();
  void addGnssFix(const GnssFixMeasurement& fix);
  void addStarAttitude(const StarAttitudeMeasurement& st);

  // Commands.
  /// Stops fusing the scope's measurements of sv_id (they stay in the diagnostics, monitored).
  void excludeSatellite(int sv_id, SatelliteScope scope = SatelliteScope::kAll);
  void readmitSatellite(int sv_id, SatelliteScope scope = SatelliteScope::kAll);
  /// Adds a bias (accelerometer [m/s^2] or gyro [rad/s], body axis 0..2) to the compensation.
  /// `bias_sigma` [same unit] is the compensation's own uncertainty: added to the bias
  /// variance, so that the filter can still estimate what the compensation missed.
  void compensateBias(bool accelerometer, int axis, double bias, double bias_sigma = 0.0);
  /// A fused receiver's clock (0: the first) jumped by `jump_m` (c times the step [m]; what
  /// its pseudoranges gained), known to `sigma_m` [m]: the clock estimate follows (before the
  /// filter is initialised, the alignment's least-squares clock already does).
  void compensateReceiverClock(double jump_m, double sigma_m, int receiver = 0);
  /// A bias step of unknown size: its variance grows by sigma^2 and the filter re-estimates it.
  void relearnBias(bool accelerometer, int axis, double sigma) {
    compensateBias(accelerometer, axis, 0.0, sigma);
  }
  /// An IMU axis has failed: its error becomes a random-walk bias (IntegratedFilter::
  /// setAxisFailed) and an aided solution reports kAidedAxisFailed. Free inertial navigation
  /// keeps its mode and shows the failure in the status (its sigmas grow with the bias walk).
  void failSensorAxis(bool accelerometer, int axis);
  void restoreSensorAxis(bool accelerometer, int axis);
  bool anyAxisFailed() const { return failed_axes_ != 0; }
  /// False when the structure does not apply to the aiding mode (see the .cpp).
  bool selectFusion(FusionStructure s);
  void markInertialLost();
  void reset();
  /// The end of a post-processing run: records the epoch still pending in the smoothing log.
  void closeSmoothingLog();

  bool initialized() const;
  const NavState& state() const;
  const StateMatrix& covariance() const;
  /// The states the filter estimates now (the others keep their variance, uncorrected).
  const StateMask& activeStates() const;
  /// Estimated sensor biases, the compensation commanded so far included: accelerometer
  /// [m/s^2, body], gyro [rad/s, body].
  Eigen::Vector3d accelBias() const;
  Eigen::Vector3d gyroBias() const;
  /// What the engine and its filter remove from each raw increment (the biases above and the
  /// filter's scale factors): what an output propagated from the state must remove too.
  ImuCorrection imuCorrection() const;
  /// Estimated star-tracker bias [rad, star-tracker body axes] (zero when not modelled).
  Eigen::Vector3d starTrackerBias() const;
  /// The estimated residual mounting misalignment [rad, body] and whether it is modelled
  /// (IntegratedFilter::mountingMisalignment; its sigmas: covariance(), kMountingMisalignment).
  Eigen::Vector3d mountingMisalignment() const;
  bool modelsMountingMisalignment() const;
  double clockBias(int receiver = 0) const;   ///< a fused receiver's clock bias c*b [m]
  double clockDrift(int receiver = 0) const;  ///< a fused receiver's clock drift c*f [m/s]
  EngineMode mode() const {
    return (status_ & kStatusReinitialising) != 0 ? EngineMode::kReinitialising : mode_;
  }
  /// False while the consistency monitor's window fails its test or the filter waits to
  /// re-initialise: the covariance does not describe the error, whatever it says.
  bool trustworthy() const {
    return (status_ & (kStatusInconsistent | kStatusReinitialising)) == 0;
  }
  const ConsistencyMonitor& consistency() const { return consistency_; }
  /// The adaptive noise of one aiding stream: its current scale on R and its counters.
  const NoiseScaleEstimator& noiseScale(NoiseStream s) const {
    return noise_scales_[static_cast<std::size_t>(s)];
  }
  /// The adaptive process noise: its current scale on Q and its counters.
  const ProcessNoiseScaleEstimator& processNoiseScale() const { return process_noise_; }
  FusionStructure fusion() const;
  const EngineConfig& config() const { return config_; }
  std::uint32_t status() const { return status_; }
  const EngineCounters& counters() const { return counters_; }
  /// Satellite epochs whose pseudorange error had no state (every state taken) since the start.
  std::uint64_t pseudorangesWithoutErrorState() const;
  /// The latest fused pseudorange epoch's diagnostics (innovations, S, H, K, Phi).
  const EpochDiagnostics& lastEpoch() const;
  /// StartSource::kAligned: where the alignment stands, and once aligned what it started from
  /// (attitude and position sources, its sigmas, the gyrocompassing limit; valid once the
  /// phase is kAligned), and the pseudorange epochs whose least-squares solution failed.
  AlignmentPhase alignmentPhase() const;
  const AlignedStart& alignedStart() const;
  std::uint64_t alignmentFailedSolutions() const;
  /// Horizontal and vertical protection levels of the current state (kNotMonitored unless
  /// integrity is enabled in tightly coupled mode and the filter runs).
  ProtectionLevels protectionLevels() const;
  /// Pseudorange epochs the protection levels took, and refused (not finite).
  std::uint64_t protectionLevelEpochs() const;
  std::uint64_t protectionLevelEpochsRefused() const;
  /// ... and those at which its detector declared a fault (on fixes: the levels unavailable).
  std::uint64_t protectionLevelDetections() const;

 private:
  StateMask baseMask() const;
  /// The white part of a star-tracker sample's sigma, per body axis [rad].
  Eigen::Vector3d starTrackerWhiteSigma(const Eigen::Vector3d& sigma_b_rad) const;
  EngineMode aidedMode() const;
  void applyStage(const StageDecision& d);
  /// Along the body's forward axis, from the latest increment [m/s^2].
  double longitudinalAcceleration() const;
  void constraintUpdate();
  void countGated(const ScalarUpdateResult* results, int n);
  void start(const NavState& state, double clock_bias_m, double clock_drift_mps,
             const StateMatrix& initial_covariance);
  void startFromAlignment();
  /// Inertial data is missing from the state time to `start_ns`: propagated across with held
  /// inputs, or restarted beyond GapBridgeConfig::max_bridged_s; the covariance grows for what
  /// was not measured.
  void crossGap(std::int64_t start_ns);
  StateMatrix alignedCovariance(const AlignedStart& a) const;
  /// While the course check is armed: the Earth-rate remainder's floor, and at rest the
  /// gyrocompass heading's (IntegratedFilter).
  void floorBeforeCourseCheck();
  /// Once after a gyrocompassing start whose heading sigma is above the configured limit, at
  /// the first GNSS velocity faster than course_min_speed_mps: the GNSS course against the
  /// INS course (IntegratedFilter::correctHeadingFromCourse), before the acceleration that
  /// brought the vehicle there goes on through a heading error the first-order model cannot
  /// carry. The INS velocity must have been gained from rest: the start was at rest.
  void checkHeadingFromCourse(const Eigen::Vector3d& gnss_vel_ned_mps,
                              double cross_track_sigma_mps);
  bool aligning() const;
  /// One aiding epoch's normalized innovations to the consistency monitor; a lasting alarm
  /// asks for re-initialisation (engine_consistency.cpp).
  void checkConsistency(std::int64_t time_ns, const ScalarUpdateResult* rows, int n);
  void checkConsistency(std::int64_t time_ns, const std::vector<MeasurementReport>& reports);
  /// A fused fix's innovations (whitened rows, R's sigmas) into config_.fix_innovation_log.
  void logFixInnovations(const std::array<ScalarUpdateResult, 3>& position,
                         const Eigen::Vector3d& pos_sigma_m,
                         const std::array<ScalarUpdateResult, 3>& velocity,
                         const Eigen::Vector3d& vel_sigma_mps);
  /// A fused fix as one epoch (filter/epoch_diagnostics.hpp, kFixAxisSources; loose coupling
  /// and the multi-dimensional filter) to the protection levels' detector and the adaptive
  /// process noise (`process_part`: P_Q before the updates), as configured.
  void fixEpoch(std::int64_t time_ns, FixEpochInput& epoch,
                const std::array<ScalarUpdateResult, 3>& p,
                const std::array<ScalarUpdateResult, 3>& v, const StateMatrix& process_part);
  /// The protection levels' detector watches pseudoranges (and the fault manager acts on its
  /// decisions) rather than fixes.
  bool integrityOnPseudoranges() const;
  void judgeConsistency(std::int64_t time_ns, double nis, int dof);
  void askReinitialisation();
  /// While re-initialisation is asked: from this epoch's pseudorange solution (false: not
  /// possible, fewer than four satellites) or from a fix.
  bool reinitialiseFromPseudoranges(std::int64_t time_ns);
  void reinitialiseFromFix(const GnssFixMeasurement& fix);
  void finishReinitialisation();

  EngineConfig config_;
  Indirect<IntegratedFilter> filter_;
  Indirect<InitialAligner> aligner_;
  Indirect<GlrProtectionLevel> integrity_;
  Indirect<StationarityDetector> stationarity_;
  Indirect<StageSelector> stages_;
  ConsistencyMonitor consistency_;
  /// A fix as the protection levels' detector sees it (storage reused from fix to fix, rewritten
  /// by each: not in the recovery history's copies of the engine).
  Scratch<EpochDiagnostics> fix_epoch_;
  AppliedGain fix_gain_;
  std::array<NoiseScaleEstimator, kNoiseStreams> noise_scales_;
  ProcessNoiseScaleEstimator process_noise_;
  /// A GNSS epoch's accepted rows (from the prior, `process_part` the P_Q it was taken with)
  /// to the process-noise scale, which the filter propagates with from now on.
  void adaptProcessNoise(std::int64_t time_ns, const EpochDiagnostics& d,
                         const StateMatrix& process_part);
  /// The stream's sigma factor for this epoch: sqrt of its scale on R.
  double noiseSigmaFactor(NoiseStream s) const;
  /// The epoch's rows fused with that stream's scale: they feed its next estimate.
  void adaptNoise(NoiseStream s, const ScalarUpdateResult* rows, int n);
  EngineMode mode_{EngineMode::kInitializing};
  std::uint32_t status_{0};
  EngineCounters counters_;
  std::map<int, std::uint8_t> excluded_;  ///< sv -> SatelliteScope bits excluded
  /// Reused buffer of the satellites fused (each epoch rewrites it: not in the recovery
  /// history's copies of the engine).
  Scratch<std::vector<SatelliteObservation>> used_;
  /// The first receiver's satellites of used_ (alignment, re-initialisation, course check).
  Scratch<std::vector<SatelliteObservation>> first_receiver_;
  /// The fused receivers' epochs of one time, waiting to be fused as one (holdGnssEpoch).
  struct HeldEpoch {
    std::int64_t time_ns{0};
    std::uint8_t receivers{0};  ///< bit r: receiver r's epoch is in
    std::vector<SatelliteObservation> satellites;
  };
  HeldEpoch held_;
  /// Bit r: fused receiver r's clock has been started since the filter was (receiver 0's
  /// with the filter itself).
  std::uint8_t clocks_started_{1};
  /// used_ with the first receiver's satellites only (used_ itself when there is one).
  const std::vector<SatelliteObservation>& firstReceiverObservations();
  /// Starts each further receiver's clock from its first epoch in used_, whose satellites then
  /// leave this epoch.
  void startReceiverClocks();
  Eigen::Vector3d accel_compensation_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d gyro_compensation_{Eigen::Vector3d::Zero()};
  std::uint8_t failed_axes_{0};  ///< bit i: accelerometer i (0-2), gyro i - 3 (3-5)
  std::int64_t next_output_ns_{0};
  std::int64_t last_fix_ns_{-1};
  /// That fix's horizontal ground speed less 3 of its sigmas: the speed it proves [m/s].
  double last_fix_moving_speed_mps_{0.0};
  /// The latest increment integrated (compensated): held across a gap (ins/gap_bridge.hpp).
  std::optional<ImuIncrement> last_increment_;
  /// The latest increment's bias-corrected angular rate [rad/s, body] (the antenna's velocity).
  Eigen::Vector3d bodyRate() const;
  /// The fix's position brought to the filter state's time along the fix's velocity.
  earth::Geodetic fixPositionAtStateTime(const GnssFixMeasurement& fix) const;
  /// The fix's velocity brought from its time of validity to the state's time by the velocity
  /// change the mechanization integrated in between (GnssFixMeasurement::velocity_time_offset_ns).
  Eigen::Vector3d fixVelocityAtStateTime(const GnssFixMeasurement& fix);
  VelocityHistory velocity_history_;
  std::int64_t next_constraint_ns_{0};
  bool course_check_armed_{false};             ///< checkHeadingFromCourse still to come
  double gyrocompass_heading_sigma_rad_{0.0};  ///< the aligned start's heading sigma
};

}  // namespace navbus::core
