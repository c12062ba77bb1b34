#include "navbus/sim/star_tracker_model.hpp"

#include <cmath>

#include "navbus/core/math/rotation.hpp"

namespace navbus::sim {

StarTrackerModel::StarTrackerModel(const StarTrackerSpec& spec, std::uint64_t seed)
    : spec_(spec), rng_(seed) {
  for (int i = 0; i < 3; ++i) bias_[i] = spec.bias_rad * unit_(rng_);  // stationary start
}

std::optional<Eigen::Quaterniond> StarTrackerModel::measure(const Eigen::Quaterniond& q_true,
                                                            double dt) {
  const double phi = std::exp(-dt / spec_.bias_correlation_time_s);
  const double w = spec_.bias_rad * std::sqrt(1.0 - phi * phi);
  Eigen::Vector3d err;
  for (int i = 0; i < 3; ++i) {
    bias_[i] = phi * bias_[i] + w * unit_(rng_);
    err[i] = bias_[i] + spec_.noise_rad * unit_(rng_);
  }
  // Draw the dropout last so that the noise sequence does not depend on the probability.
  if (uniform_(rng_) < spec_.dropout_probability) return std::nullopt;
  // The error is a small rotation of the body frame: q_meas = q_true * exp(err).
  return (q_true * core::quaternionFromRotationVector(err)).normalized();
}

}  // namespace navbus::sim
