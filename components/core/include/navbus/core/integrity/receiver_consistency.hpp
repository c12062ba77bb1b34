// Consistency of redundant GNSS receivers on one vehicle (Sturza, "Navigation system integrity
// monitoring using redundant measurements", 1988, applied across receivers):
//
// 1. Shared satellites. Receiver r's pseudorange of satellite k, against the reference
//    receiver's of the same epoch (satellite clock applied in both), is the single difference
//
//      d_k = rho_ref,k - rho_r,k = -u_k . b + c (dt_ref - dt_r) + e_k                       (1)
//
//    with u_k the line of sight and b = antenna_r - antenna_ref: the satellite's clock, orbit
//    and most of the atmosphere cancel. The geometric term is at most |b| (the vehicle's
//    attitude is not the fault manager's), taken as noise of sigma |b| / sqrt(3) beside the two
//    receivers' noise. Every d_k shares one unknown, the clock difference: a common-mode parity
//    space (parity_space.hpp, makeCommonMode) whose GLR (parity_glr.hpp, seed 000's eqs. 9-13)
//    isolates a satellite whose pseudorange differs in one receiver (spoofed, multipath). With
//    two receivers the data cannot say in which (the sign of a difference): the decision names
//    the satellite and both receivers.
// 2. Each receiver's clock. Its least-squares clock bias (gnss_fix.hpp) against the prediction
//    from its previous epoch,
//
//      v = c dt(t) - (c dt(t0) + c dt'(t0) (t - t0)),
//      var v = sigma_b(t)^2 + sigma_b(t0)^2 + (sigma_d(t0) (t - t0))^2 + q_b (t - t0) + q_d (t -
//      t0)^3 / 3  (2)
//
//    (sigma_b = TDOP sigma of the pseudoranges, sigma_d = TDOP sigma of the rates; q the
//    clock's random walks, seed 000 eq. 3); v^2 / var v beyond the chi-square quantile of the
//    false-alarm probability is a clock jump of that receiver, of size v. The monitor then
//    follows the new clock.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "navbus/core/gnss/gnss_fix.hpp"
#include "navbus/core/integrity/parity_glr.hpp"

namespace navbus::core {

/// One satellite's measurement in one receiver epoch (satellite clock applied).
struct ReceiverSatellite {
  int sv_id{0};
  RangeObservation range;
  double pseudorange_sigma_m{0.0};
  double rate_sigma_mps{0.0};
};

struct ReceiverClockConfig {
  double false_alarm_probability{1e-9};    ///< per epoch
  double bias_noise_m_per_sqrts{0.1};      ///< q_b = this^2 (seed 000 eq. 3 w1)
  double drift_noise_mps_per_sqrts{0.01};  ///< q_d = this^2 (w2)
};

struct ClockJump {
  double magnitude_m{0.0};  ///< v: the jump in c * clock [m]
  double statistic{0.0};    ///< v^2 / var v
  double threshold{0.0};
};

/// Eq. 2 for one receiver.
class ReceiverClockMonitor {
 public:
  explicit ReceiverClockMonitor(const ReceiverClockConfig& config);
  /// The receiver's epoch at `time_s`; a jump when its clock left the prediction. Epochs with
  /// fewer than 4 satellites (no fix) restart the prediction.
  std::optional<ClockJump> update(double time_s, const std::vector<ReceiverSatellite>& satellites);
  double threshold() const { return threshold_; }
  double largestStatistic() const { return largest_; }

 private:
  ReceiverClockConfig config_;
  double threshold_;
  bool have_previous_{false};
  double time_s_{0.0}, bias_m_{0.0}, drift_mps_{0.0}, bias_sigma_m_{0.0}, drift_sigma_mps_{0.0};
  Eigen::Vector3d position_ecef_m_{Eigen::Vector3d::Zero()};  ///< the last fix: next start
  std::vector<RangeObservation> ranges_;                      ///< scratch
  double largest_{0.0};
};

struct PairConsistencyResult {
  ParityGlrResult glr;      ///< instrument indices into `sv_ids`
  std::vector<int> sv_ids;  ///< the shared satellites tested this epoch, in instrument order
  int sv_id{0};             ///< glr.detected: the satellite isolated
  int runner_up_sv{0};      ///< ... and the one it cannot be told from (0: none)
};

/// Eq. 1 between the reference receiver and one other.
class ReceiverPairConsistency {
 public:
  /// `baseline_m`: |antenna_r - antenna_ref|.
  ReceiverPairConsistency(const ParityGlrConfig& config, double baseline_m);
  /// One epoch of both receivers (same time). The test restarts when the shared set changes;
  /// it needs at least two shared satellites not excluded.
  const PairConsistencyResult& update(const std::vector<ReceiverSatellite>& reference,
                                      const std::vector<ReceiverSatellite>& other);
  /// A satellite leaves the test (after its decision).
  void exclude(int sv_id);
  /// The minimum detectable difference of the latest space's satellites [m] (0 without one).
  double minimumDetectableDifference() const;
  const std::string& lastError() const { return error_; }

 private:
  ParityGlrConfig config_;
  double baseline_variance_m2_;
  std::vector<int> excluded_;
  std::optional<ParityGlr> glr_;
  PairConsistencyResult result_;
  parity::Measurements differences_, sigmas_;
  std::string error_;
};

}  // namespace navbus::core
