// Star tracker (seed 001): inertial attitude with white noise and a first-order Gauss-Markov
// bias per body axis, and dropouts (no solution) of a given probability per sample.
#pragma once

#include <cstdint>
#include <optional>
#include <random>

#include <Eigen/Geometry>

#include "navbus/core/math/units.hpp"

namespace navbus::sim {

struct StarTrackerSpec {
  double noise_rad{0.3 * units::kArcsec};  ///< white, 1 sigma per axis (0.3 arcsec)
  double bias_rad{0.0};                    ///< Gauss-Markov bias, 1 sigma per axis
  double bias_correlation_time_s{300.0};
  double dropout_probability{0.0};  ///< per sample
};

class StarTrackerModel {
 public:
  StarTrackerModel(const StarTrackerSpec& spec, std::uint64_t seed);
  /// Measures q_b_to_i over an interval dt since the previous call; nullopt when dropped out.
  std::optional<Eigen::Quaterniond> measure(const Eigen::Quaterniond& q_b_to_i_true, double dt);
  /// Current bias (rotation vector, body frame), for truth files and tests.
  const Eigen::Vector3d& bias() const { return bias_; }

 private:
  StarTrackerSpec spec_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_{0.0, 1.0};
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  Eigen::Vector3d bias_;
};

}  // namespace navbus::sim
