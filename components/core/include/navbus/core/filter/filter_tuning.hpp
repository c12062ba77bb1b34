// The integrated filter's configuration: its fusion structure and tuning (process noise,
// initial sigmas, gate, star-tracker bias, adaptive, failed-axis and federated parameters).
// Apart from the filter so that the engine's configuration can name it without the filter.
#pragma once

#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/units.hpp"

namespace navbus::core {

enum class FusionStructure { kCentralized, kFederated, kAdaptive };

struct FilterTuning {
  earth::GravityModel gravity{earth::GravityModel::kWgs84Normal};
  // Process noise densities.
  double accel_noise_mps2_per_sqrthz{10.0 * units::kMicroG};       ///< 10 ug/sqrt(Hz)
  double gyro_noise_radps_per_sqrthz{0.001 * units::kDeg / 60.0};  ///< 0.001 deg/sqrt(h)
  double clock_bias_noise_m_per_sqrts{0.1};
  double clock_drift_noise_mps_per_sqrts{0.01};
  /// Random walk of the sensor biases (a MEMS bias wanders; 0: the biases are constants, as the
  /// simulator's are).
  double accel_bias_rw_mps2_per_sqrts{0.0};
  double gyro_bias_rw_radps_per_sqrts{0.0};
  // Initial 1-sigma (also the values the covariance reset rules re-initialize to).
  double pos_sigma_m{40.0};
  double vel_sigma_mps{1.0};
  double level_sigma_rad{1e-3};
  double heading_sigma_rad{5.0 * 1e-3};
  double accel_bias_sigma_mps2{1000.0 * units::kMicroG};     ///< 1000 ug
  double gyro_bias_sigma_radps{1.0 * units::kDeg / 3600.0};  ///< 1 deg/h
  double clock_bias_sigma_m{3000.0};
  double clock_drift_sigma_mps{1.0};
  // Scale-factor errors of the accelerometers and gyros (layout::kAccelScale, kGyroScale): a
  // random constant per axis when its sigma is positive (0: not modelled, the states inactive).
  double accel_scale_sigma{0.0};  ///< 1 sigma [1] (1e-3: 1000 ppm)
  double gyro_scale_sigma{0.0};   ///< 1 sigma [1]
  double gate_sigma{5.0};         ///< innovation gate in standard deviations; <= 0: no gate
  /// The longest interval one covariance propagation covers [s]: 0 propagates it with every
  /// increment; a longer one gathers the increments' error dynamics and process noise until an
  /// update, a solution epoch or the period's end needs it (propagation_interval.hpp). The
  /// mechanization runs every increment either way.
  double covariance_period_s{0.0};
  // Star-tracker bias (seed 001): a first-order Gauss-Markov rotation about each star-tracker
  // axis, modelled as the layout's kStarTrackerBias states when its sigma is positive (0: not
  // modelled, the states stay inactive).
  double star_tracker_bias_sigma_rad{0.0};             ///< stationary 1 sigma per axis [rad]
  double star_tracker_bias_correlation_time_s{300.0};  ///< [s]
  // Residual mounting misalignment of a land vehicle (layout::kMountingMisalignment): random
  // constants with this 1 sigma per body axis when positive (0: not modelled), plus a random
  // walk (a body that settles on its suspension).
  double mounting_misalignment_sigma_rad{0.0};         ///< 1 sigma per axis [rad]
  double mounting_misalignment_rw_rad_per_sqrts{0.0};  ///< [rad/sqrt(s)]
  // Time-correlated pseudorange errors (tight coupling): a first-order Gauss-Markov state per
  // tracked satellite (layout::kPseudorangeError, pseudorange_error_slots.hpp) when the sigma
  // is positive (0: not modelled, pseudoranges fused with their white sigma only).
  double pseudorange_error_sigma_m{0.0};               ///< stationary 1 sigma [m]
  double pseudorange_error_correlation_time_s{300.0};  ///< [s]
  // Time-correlated error of the GNSS fix's position (loose coupling, layout::kFixPositionError):
  // a first-order Gauss-Markov state per NED axis when the horizontal sigma is positive (0: not
  // modelled, the fixes fused with their white sigmas only).
  double fix_position_error_sigma_h_m{0.0};            ///< stationary 1 sigma, N and E [m]
  double fix_position_error_sigma_v_m{0.0};            ///< stationary 1 sigma, D [m]
  double fix_position_error_correlation_time_s{30.0};  ///< [s]
  // Adaptive structure (seed 001 eqs. 30-34).
  int adaptive_window{50};                ///< innovations per estimate [epochs]
  double adaptive_floor_position_m{0.3};  ///< sqrt(xi) for position [m]
  double adaptive_floor_velocity_mps{0.01};
  double adaptive_floor_attitude_rad{0.2 * units::kArcsec};
  bool adaptive_floor_at_reported{true};  ///< R never below the measurement's own R
  // A failed IMU axis (CMD_FAIL_SENSOR_AXIS): its output error (a stuck value minus the true
  // specific force or rate) is modelled as a bias with this random walk, and its variance grows
  // by the sigma at the failure. The walk must cover the vehicle's manoeuvres on that axis.
  double failed_accel_bias_sigma_mps2{1.0};
  double failed_accel_bias_rw_mps2_per_sqrts{1.0};
  double failed_gyro_bias_sigma_radps{0.02};
  double failed_gyro_bias_rw_radps_per_sqrts{0.005};
  // Federated structure: each local filter starts from, and is driven by, share times the
  // covariance and process noise (information sharing 1/share, Carlson's no-reset mode).
  double federated_share{2.0};
};

}  // namespace navbus::core
