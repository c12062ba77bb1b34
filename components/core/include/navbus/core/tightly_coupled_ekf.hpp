// The 17-state tightly coupled error-state EKF of seed 000 with feedback: strapdown
// mechanization corrected by the estimated biases, covariance propagation with the error
// dynamics of ins_error_model.hpp, sequential Joseph-form pseudorange and pseudorange-rate
// updates with gating, and the reset of the error state into the navigation state.
#pragma once

#include <array>
#include <vector>

#include "navbus/core/aiding_measurements.hpp"
#include "navbus/core/gnss_measurement.hpp"
#include "navbus/core/ins_error_model.hpp"
#include "navbus/core/kalman_update.hpp"

namespace navbus::core {

struct TightlyCoupledConfig {
  earth::GravityModel gravity{earth::GravityModel::kWgs84Normal};
  // Process noise densities.
  double accel_noise_mps2_per_sqrthz{1e-4};
  double gyro_noise_radps_per_sqrthz{1e-6};
  double clock_bias_noise_m_per_sqrts{0.1};
  double clock_drift_noise_mps_per_sqrts{0.01};
  // Initial 1-sigma.
  double pos_sigma_m{40.0};
  double vel_sigma_mps{1.0};
  double level_sigma_rad{1e-3};
  double heading_sigma_rad{5e-3};
  double accel_bias_sigma_mps2{1e-2};
  double gyro_bias_sigma_radps{5e-6};
  double clock_bias_sigma_m{3000.0};
  double clock_drift_sigma_mps{1.0};
  double gate_sigma{5.0};  ///< innovation gate in standard deviations
};

struct MeasurementReport {
  int sv_id;
  bool rate;  ///< false: pseudorange row, true: pseudorange-rate row
  ScalarUpdateResult result;
};

/// Everything the GLR detector (seed 000 eqs. 6-16) needs from one GNSS epoch, in batch form
/// from the prior covariance: rows are (pseudorange, rate) per satellite, in order.
struct EpochDiagnostics {
  std::vector<int> sv_ids;             ///< per row
  std::vector<bool> is_rate;           ///< per row
  Eigen::VectorXd innovation;          ///< predicted minus measured, m rows
  Eigen::MatrixXd innovation_cov;      ///< V = H P- H^T + R, m x m
  Eigen::MatrixXd h;                   ///< m x 17
  Eigen::MatrixXd k;                   ///< 17 x m, K = P- H^T V^-1
  Matrix17 phi{Matrix17::Identity()};  ///< transition accumulated since the previous epoch
  std::vector<double> test_ratio;      ///< per row, from the sequential gated update
};

class TightlyCoupledEkf {
 public:
  using Vector17 = Eigen::Matrix<double, tc17::kSize, 1>;

  void initialize(const NavState& state, double clock_bias_m, double clock_drift_mps,
                  const TightlyCoupledConfig& config);
  /// Mechanizes one increment (bias-corrected) and propagates the covariance and the clock.
  void propagate(const ImuIncrement& raw);
  /// Processes one epoch of measurements at the current state time; returns one report per row.
  std::vector<MeasurementReport> update(const std::vector<SatelliteObservation>& sats);

  /// Processes a three-component aiding measurement (loosely coupled position, velocity, star
  /// tracker attitude), one decorrelated row at a time; returns the three row results.
  std::array<ScalarUpdateResult, 3> update(const VectorMeasurement& m);

  const NavState& state() const { return ins_.state(); }
  const Matrix17& covariance() const { return P_; }
  const Eigen::Vector3d& accelBias() const { return accel_bias_; }
  const Eigen::Vector3d& gyroBias() const { return gyro_bias_; }
  double clockBias() const { return clock_bias_m_; }
  double clockDrift() const { return clock_drift_mps_; }
  /// Transition matrix accumulated since the previous update (for the GLR diagnostics).
  const Matrix17& accumulatedPhi() const { return phi_since_update_; }
  /// Diagnostics of the latest GNSS epoch.
  const EpochDiagnostics& lastEpoch() const { return last_epoch_; }
  /// Restarts the integration at a new time without propagating across missing data.
  void restartAt(std::int64_t time_ns) { ins_.restartAt(time_ns); }
  bool initialized() const { return ins_.initialized(); }

 private:
  void feedback(const Vector17& dx);

  TightlyCoupledConfig config_;
  StrapdownNed ins_;
  Matrix17 P_{Matrix17::Zero()};
  Matrix17 phi_since_update_{Matrix17::Identity()};
  EpochDiagnostics last_epoch_;
  Eigen::Vector3d accel_bias_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d gyro_bias_{Eigen::Vector3d::Zero()};
  double clock_bias_m_{0.0};
  double clock_drift_mps_{0.0};
};

}  // namespace navbus::core
