// Ring-laser-gyro dither as seen in the raw high-rate stream (seed 003, eqs. 1-2).
// Each gyro is dithered sinusoidally at its own frequency with a peak rate that varies randomly
// between the configured bounds (random dither amplitude against lock-in): uniform random knots
// every `amplitude_knot_s`, linearly interpolated, so the modulation sidebands stay within a few
// tens of Hz of the carrier and the trapping lines at |f_i - f_j| stay visible. Each
// accelerometer picks up the dither of all three gyros (its own axis weaker); with trapping,
// each gyro output also carries the difference frequencies |f_i - f_j|. The navigation-rate
// increments are dither-stripped: the dither terms are in the raw stream only.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "navbus/core/math/units.hpp"

namespace navbus::sim {

struct DitherSpec {
  Eigen::Vector3d frequency_hz{373.0, 441.0, 409.0};  ///< x, y, z gyros (unit tested in seed 003)
  double peak_rate_min_radps{70.0 * units::kDeg};
  double peak_rate_max_radps{130.0 * units::kDeg};
  double accel_cross_axis_mps2{
      5.0 * 1e-3 *
      units::kStandardGravity};  ///< 5 mg  ///< dither of another axis seen by an accelerometer
  double accel_own_axis_mps2{1.0 * 1e-3 * units::kStandardGravity};  ///< own axis: weaker
  double amplitude_knot_s{0.05};  ///< spacing of the random peak-rate knots
  double trapping_rate_radps{0.5 *
                             units::kDeg};  ///< difference-frequency amplitude in gyro outputs
  std::uint64_t seed{1};
};

struct DitherSample {
  Eigen::Vector3d angular_rate_b_radps{Eigen::Vector3d::Zero()};   ///< dither + trapping
  Eigen::Vector3d specific_force_b_mps2{Eigen::Vector3d::Zero()};  ///< coupled dither
};

class DitherModel {
 public:
  explicit DitherModel(const DitherSpec& spec) : spec_(spec) {}
  /// Dither terms at time t seconds after the start (deterministic for a given seed).
  DitherSample at(double t) const;
  /// Peak rate of gyro `axis` at time t.
  double peakRate(int axis, double t) const;
  const DitherSpec& spec() const { return spec_; }

 private:
  DitherSpec spec_;
};

}  // namespace navbus::sim
