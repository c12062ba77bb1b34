// The multi-dimensional filter of seed 004 (section IV, figs. 8-9): which reduced filter runs,
// chosen from stationarity and GNSS availability, and the covariance resets at each switch.
//   F1  8 states, zero-velocity updates while stationary (eq. 13: dV, phi_N, phi_E, bias_z,
//       eps_x, eps_y; the states eq. 9 shows observable when standing still),
//   F2 15 states, GNSS position and velocity while moving (eqs. 2, 5),
//   F3  9 states (position, velocity, attitude) for the first seconds after GNSS returns
//       (eq. 14),
//   F4 12 states, non-holonomic constraints during outages (eq. 15: no position).
// Switch resets (eq. 12): FS zeroes the off-diagonal covariance; FS/A (stationary -> moving)
// also re-initializes the horizontal attitude and velocity variances; FS/I (outage -> GNSS)
// re-initializes the position, velocity and attitude variances and keeps the biases.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "navbus/core/filter/error_state.hpp"
#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

enum class MdfStage { kF1ZeroVelocity, kF2Gnss, kF3Recovery, kF4Constraint };

/// How the land-vehicle filter handles stops and outages: the multi-dimensional filter, or the
/// comparison cases of seed 004 (section IV.3): the 15-state filter is interrupted during the
/// outage (the mechanization runs on, the covariance is not propagated) and, when GNSS returns,
/// I: resumes as it was; II: resumes with its whole covariance re-initialized.
enum class MdfPolicy { kMultiDimensional, kContinue, kResetAll };

/// What a reduced filter does with the states it does not estimate: seed 004 drops them (they
/// keep their variance, lose their correlations and are not propagated), which makes the
/// reduced filters overconfident: standing still, the tilt absorbs the horizontal accelerometer
/// biases F1 leaves out, and F4's frozen position variance stops growing while the position
/// error does. As consider states (Schmidt-Kalman) they are propagated and correlated like the
/// 15-state filter's but never corrected, so each stage still estimates only its own states.
enum class ReducedStates { kDropped, kConsidered };

/// How a stage switch's covariance reset (eq. 12) is applied: as the paper writes it (zero
/// every off-diagonal element, then set the listed variances), or by raising each listed
/// variance to at least its sigma and keeping the correlations. The paper's form forgets what
/// is known jointly: after levelling the tilt error is the horizontal accelerometer bias over g,
/// and with their correlation zeroed the filter is overconfident about their difference (tilt
/// NEES 2-4 per axis after the start, 40 runs).
enum class ResetForm { kPaper, kInflate };

enum class CovarianceReset { kNone, kFs, kFsA, kFsI, kAll };

/// The active states of each reduced filter (clock states never: this filter is loosely
/// coupled).
StateMask stageMask(MdfStage stage);

struct StationarityConfig {
  double window_s{1.0};          ///< detection window
  double accel_std_mps2{0.03};   ///< specific-force scatter below this ...
  double gyro_std_radps{0.005};  ///< ... and angular-rate scatter below this ...
  double speed_mps{0.3};         ///< ... and estimated ground speed below this: stationary
};

/// Stationarity from the increments (per-axis scatter of specific force and rate over a
/// window) and the estimated speed: a vehicle cruising smoothly has a quiet IMU too, the speed
/// tells them apart.
class StationarityDetector {
 public:
  static constexpr int kMaxWindow = 512;
  void configure(const StationarityConfig& c, double imu_period_s);
  /// Adds an increment; returns the decision for the current window.
  bool update(const ImuIncrement& inc, double speed_mps);
  bool stationary() const { return stationary_; }
  /// True once the window is full (no decision before).
  bool ready() const { return count_ == length_; }

 private:
  StationarityConfig config_;
  std::array<Eigen::Matrix<double, 6, 1>, kMaxWindow> samples_{};
  int length_{50};
  int count_{0};
  int next_{0};
  bool stationary_{false};
};

struct MdfConfig {
  MdfPolicy policy{MdfPolicy::kMultiDimensional};
  ReducedStates unestimated{ReducedStates::kConsidered};
  ResetForm reset_form{ResetForm::kInflate};
  StationarityConfig stationarity;
  double recovery_s{5.0};           ///< F3 duration after GNSS returns (seed 004: 5 s)
  double gnss_timeout_s{1.5};       ///< GNSS counts as lost after this long without a fix
  double constraint_period_s{0.1};  ///< ZUPT / NHC update period
  double zupt_sigma_mps{0.01};
  double nhc_sigma_mps{0.1};
};

struct StageDecision {
  MdfStage stage;
  CovarianceReset reset;
  bool changed;
};

/// The switching logic of fig. 8 for the multi-dimensional policy; for the comparison cases
/// the stage still names what the vehicle is doing, but the filter keeps 15 states.
class StageSelector {
 public:
  void configure(const MdfConfig& c) { config_ = c; }
  StageDecision update(bool stationary, bool gnss_available, std::int64_t time_ns);
  MdfStage stage() const { return stage_; }
  void restart() { started_ = false; }

 private:
  MdfConfig config_;
  MdfStage stage_{MdfStage::kF1ZeroVelocity};
  bool started_{false};
  std::int64_t recovery_start_ns_{0};
};

}  // namespace navbus::core
