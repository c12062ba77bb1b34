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
#include "navbus/core/filter/mdf_config.hpp"
#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

/// The active states of each reduced filter (clock states never: this filter is loosely
/// coupled).
StateMask stageMask(MdfStage stage);

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
