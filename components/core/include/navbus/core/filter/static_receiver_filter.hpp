// GNSS-only filter of a receiver at rest (a surveyed antenna, a parked vehicle), for real
// pseudorange data without an IMU. It runs over the state layout of the tightly coupled
// filter (state_layout.hpp) with the position and clock blocks active: the position is
// constant, the receiver clock bias and drift are random walks as in seed 000 eq. 3; velocity,
// attitude and IMU biases are inactive (zero, no variance). Pseudorange rows only. Its epochs
// are the same EpochDiagnostics the tightly coupled filter publishes, so that the GLR monitors
// it unchanged (the IMU hypotheses have no signature here and are switched off in its
// configuration). Errors are estimate minus truth; position errors in NED at the estimate.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "navbus/core/filter/epoch_diagnostics.hpp"
#include "navbus/core/filter/error_state.hpp"
#include "navbus/core/gnss/gnss_measurement.hpp"
#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

struct StaticReceiverTuning {
  double pos_sigma_m{30.0};          ///< initial, per axis
  double clock_bias_sigma_m{100.0};  ///< initial
  /// Initial drift sigma: a receiver TCXO runs off by up to a few ppm (1 ppm = 300 m/s; the
  /// station of the real-data test drifts at 418 m/s).
  double clock_drift_sigma_mps{1000.0};
  double clock_bias_noise_m_per_sqrts{0.1};      ///< random walk of c * bias
  double clock_drift_noise_mps_per_sqrts{0.01};  ///< random walk of c * drift
  double gate_sigma{5.0};  ///< innovation gate in standard deviations; <= 0: no gate
};

class StaticReceiverFilter {
 public:
  /// Starts at `pos_ecef_m` (e.g. the first least-squares fix) and clock at time t [s].
  void initialize(const Eigen::Vector3d& pos_ecef_m, double clock_bias_m, double time_s,
                  const StaticReceiverTuning& tuning);

  /// Propagates the clock to time t and fuses the pseudoranges of `sats` (rows of satellites
  /// whose use_range is false are monitored only). Returns the epoch's diagnostics.
  const EpochDiagnostics& update(double time_s, const std::vector<SatelliteObservation>& sats);

  bool initialized() const { return initialized_; }
  Eigen::Vector3d positionEcef() const;
  /// Position covariance [m^2] in NED at the estimate.
  Eigen::Matrix3d positionCovarianceNed() const;
  double clockBias() const { return clock_bias_m_; }
  double clockDrift() const { return clock_drift_mps_; }
  const EpochDiagnostics& lastEpoch() const { return last_epoch_; }

 private:
  void propagate(double dt_s);
  void feedback();

  StaticReceiverTuning tuning_;
  bool initialized_{false};
  double time_s_{0.0};
  NavState state_;  ///< position only (at rest: zero velocity, attitude unused)
  double clock_bias_m_{0.0};
  double clock_drift_mps_{0.0};
  ErrorState error_;
  StateMatrix phi_{StateMatrix::Identity()};
  EpochDiagnostics last_epoch_;
  AppliedGain applied_gain_;
};

}  // namespace navbus::core
