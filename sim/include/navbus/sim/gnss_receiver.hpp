// Pseudorange and pseudorange-rate generation for a receiver on or near the Earth.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "navbus/core/math/units.hpp"
#include "navbus/sim/constellation.hpp"
#include "navbus/sim/samples.hpp"

namespace navbus::sim {

struct GnssReceiverConfig {
  double elevation_mask_rad{5.0 * units::kDeg};
  int max_satellites{12};       ///< keep at most this many (highest elevation first)
  int fixed_satellites{0};      ///< >0: track only the N highest at the first epoch (seed 000: 4)
  double clock_bias_m{3000.0};  ///< c * receiver clock bias at t = 0 (seed 000 eq. 3)
  double clock_drift_mps{1.0};  ///< c * receiver clock drift at t = 0
  /// Seed 000 eq. 3: x_b' = x_f + w1, x_f' = w2, with white w1, w2 of these densities.
  double clock_bias_noise_m_per_sqrts{0.0};
  double clock_drift_noise_mps_per_sqrts{0.0};
  double pseudorange_sigma_m{3.0};  ///< white noise, 1 sigma
  double pseudorange_rate_sigma_mps{0.05};
  bool fix_least_squares{true};  ///< fixes from the pseudoranges (else the white-noise model)
  double fix_pos_sigma_m{2.5};   ///< receiver fix error model (white), 1 sigma per axis
  double fix_vel_sigma_mps{0.1};
};

class GnssReceiverModel {
 public:
  GnssReceiverModel(const GnssReceiverConfig& config, const Constellation& constellation);

  /// Measurements at reception time t_ns for a receiver at pos_ecef moving at vel_ecef,
  /// with the light-time iteration and the Sagnac (Earth rotation during flight) correction.
  GnssEpoch observe(std::int64_t t_ns, std::int64_t t0_ns, const Eigen::Vector3d& pos_ecef_m,
                    const Eigen::Vector3d& vel_ecef_mps, std::mt19937_64& rng);

  /// The receiver's fix for an epoch: least squares from its own pseudoranges and rates
  /// (fix_least_squares), else truth plus white noise with the configured sigma.
  GnssFixSample fix(const GnssEpoch& epoch, const core::earth::Geodetic& truth_pos,
                    const Eigen::Vector3d& truth_vel_ned, std::mt19937_64& rng) const;

 private:
  GnssReceiverConfig config_;
  const Constellation& constellation_;
  std::vector<int> tracked_;
  double clock_bias_m_;  ///< receiver clock state (seed 000 eq. 3)
  double clock_drift_mps_;
  double clock_time_s_{0.0};  ///< time since the start at which the clock state holds  ///<
                              ///< fixed_satellites > 0: the satellites chosen at the first epoch
};

}  // namespace navbus::sim
