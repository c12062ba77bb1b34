// The multi-dimensional filter's configuration (seed 004, multi_dimensional.hpp): the stage
// policy, what the reduced filters do with the states they leave out, the reset form, what
// counts as stationary, and the stage timing and constraint sigmas.
#pragma once

#include <array>
#include <bitset>
#include <cstddef>

#include "navbus/core/math/units.hpp"

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
/// None: every stage estimates the 15 navigation states and chooses only its constraints and
/// resets (on drive_0708 the consider states held the outage epochs inside 3 sigma_h 90.0 % of
/// the time and every stage estimating all 95.2 %: docs/real_data.md).
enum class ReducedStates { kDropped, kConsidered, kNone };

/// How a stage switch's covariance reset (eq. 12) is applied: as the paper writes it (zero
/// every off-diagonal element, then set the listed variances), or by raising each listed
/// variance to at least its sigma and keeping the correlations. The paper's form forgets what
/// is known jointly: after levelling the tilt error is the horizontal accelerometer bias over g,
/// and with their correlation zeroed the filter is overconfident about their difference (tilt
/// NEES 2-4 per axis after the start, 40 runs).
enum class ResetForm { kPaper, kInflate };

/// The blocks a stage switch's reset may touch (FS/A: velocity and level; FS/I: all four);
/// MdfConfig::reset_blocks says which of them it does touch.
enum class ResetBlock { kPosition, kVelocity, kLevel, kHeading };
inline constexpr std::size_t kResetBlocks = 4;
inline constexpr std::array<const char*, kResetBlocks> kResetBlockNames{"position", "velocity",
                                                                        "level", "heading"};

enum class CovarianceReset { kNone, kFs, kFsA, kFsI, kAll };

struct StationarityConfig {
  double window_s{1.0};                      ///< detection window
  double accel_std_mps2{0.03};               ///< specific-force scatter below this ...
  double gyro_std_radps{0.3 * units::kDeg};  ///< ... and angular-rate scatter below this ...
  /// ... and the filter's ground speed below this, unless a recent fix proves more (speed less
  /// 3 sigma above it)
  double speed_mps{0.3};
};

struct MdfConfig {
  MdfPolicy policy{MdfPolicy::kMultiDimensional};
  ReducedStates unestimated{ReducedStates::kConsidered};
  ResetForm reset_form{ResetForm::kInflate};
  /// Which blocks the resets touch (default all). Every block a reset raises is, to the
  /// smoother, process noise at the switch: a raised position variance says the vehicle may have
  /// jumped, and the fixes after an outage then no longer correct it backward.
  std::bitset<kResetBlocks> reset_blocks{(1u << kResetBlocks) - 1u};
  StationarityConfig stationarity;
  double recovery_s{5.0};           ///< F3 duration after GNSS returns (seed 004: 5 s)
  double gnss_timeout_s{1.5};       ///< GNSS counts as lost after this long without a fix
  double constraint_period_s{0.1};  ///< ZUPT / NHC update period
  double zupt_sigma_mps{0.01};
  double nhc_sigma_mps{0.1};
  /// The pitch of the velocity in body axes per unit of longitudinal acceleration [rad per
  /// m/s^2]: a car's body pitches against its track as it speeds up or brakes (navbus
  /// calibrate mounting measures it); the constraint's vertical row expects it. 0: a rigid body.
  double nhc_velocity_pitch_per_accel_rad_per_mps2{0.0};
  /// The non-holonomic constraint also while GNSS is available (stages F2 and F3), beside the
  /// fixes: what makes the mounting misalignment observable (false: seed 004's F4 only).
  bool nhc_with_gnss{false};
};

}  // namespace navbus::core
