// The least-squares combination of redundant IMUs: one filter lane on every instrument (filter
// `lanes.least_squares`). Every gyro axis of every unit senses the one body rotation increment,
// every accelerometer axis the one velocity increment of the body origin once its lever-arm term
// is removed (imu_array.hpp), so with H the included instruments' axes in body coordinates,
// W = diag(1 / sigma_i) and m their increments (Potter and Suman 1977; Sturza 1988, the
// least-squares estimate of the redundant measurements; parity_space.hpp eq. 1)
//
//   x^ = (H^T W^2 H)^-1 H^T W^2 m = E m,   cov(x^) = (H^T W^2 H)^-1                     (1)
//
// The combination carries the instruments' noise through eq. 1's covariance (sigma / sqrt(k) per
// axis for k triads) and their biases through the same weights, E b (combinedBias()). Taking an
// instrument out (a failed axis, a unit gone) changes E and so the bias the combination carries:
// generation() counts the changes, so that the lane on it re-learns its bias. Fixed capacity:
// combine() allocates nothing.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navbus/core/ins/imu_array.hpp"
#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

class ImuArrayCombination {
 public:
  static constexpr int kMaxUnits = 6;
  static constexpr int kMaxInstruments = 3 * kMaxUnits;
  using Estimator = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxInstruments>;

  /// nullopt with `error` naming the unit and the field when the array cannot be combined:
  /// fewer than 2 or more than kMaxUnits units, a mounting that is not a rotation, a lever arm
  /// that is not finite, a sigma that is not positive, an interval that is not positive.
  static std::optional<ImuArrayCombination> make(const std::vector<ImuArrayUnit>& units,
                                                 double interval_s, std::string& error);

  /// Takes the instrument out of the combination; false (and nothing changes) when the others
  /// of its kind would no longer span three axes, or it is out already or not in the array.
  bool exclude(ImuInstrument kind, int unit, int axis);
  /// Takes every instrument of the unit out (its stream ended); false as exclude().
  bool excludeUnit(int unit);
  bool included(ImuInstrument kind, int unit, int axis) const;
  /// +1 at every change of the included instruments.
  int generation() const { return generation_; }
  int units() const { return static_cast<int>(units_.size()); }

  /// One sample: increments[u] is unit u's, in its own axes, for each bit u of `present`; the
  /// result is in body axes at the body origin, at the time and interval of the first present
  /// unit's. nullopt when the present, included instruments of a kind do not span three axes.
  std::optional<ImuIncrement> combine(const std::array<ImuIncrement, kMaxUnits>& increments,
                                      std::uint32_t present);
  /// Forgets the previous sample's rate (a gap: the lever-arm term's dw/dt starts over).
  void restart() { have_previous_rate_ = false; }

  /// sqrt(diag(cov(x^))) of eq. 1 with every included instrument: the combination's noise of
  /// one sample per body axis [rad or m/s].
  Eigen::Vector3d sigma(ImuInstrument kind) const;
  /// E b: the bias the combination carries [body axes], from each unit's bias in its own axes.
  Eigen::Vector3d combinedBias(ImuInstrument kind,
                               const std::array<Eigen::Vector3d, kMaxUnits>& bias_u) const;

 private:
  ImuArrayCombination(std::vector<ImuArrayUnit> units, double interval_s);
  /// E of eq. 1 over the included instruments of the units in `present`; false when they do
  /// not span three axes. `covariance`, if given, receives (H^T W^2 H)^-1.
  bool estimator(ImuInstrument kind, std::uint32_t present, Estimator& e,
                 std::array<int, kMaxInstruments>& rows, int& n,
                 Eigen::Matrix3d* covariance = nullptr) const;
  /// The combined body vector of one kind from the measurements `m` of unit-axis instruments.
  std::optional<Eigen::Vector3d> solve(ImuInstrument kind, std::uint32_t present,
                                       const std::array<Eigen::Vector3d, kMaxUnits>& m) const;
  std::uint32_t allUnits() const { return (1u << units_.size()) - 1u; }
  /// E of every present unit, per kind (rebuilt at each change of the included instruments).
  void cacheEstimators();

  struct Cached {
    Estimator e;
    std::array<int, kMaxInstruments> rows{};
    int n{0};
  };

  std::vector<ImuArrayUnit> units_;
  double interval_s_;
  /// Bit 3 * unit + axis of each kind: the instrument is included.
  std::array<std::uint32_t, kImuInstrumentKinds> included_{};
  int generation_{0};
  std::array<Cached, kImuInstrumentKinds> all_present_{};
  Eigen::Vector3d previous_rate_b_radps_{Eigen::Vector3d::Zero()};
  bool have_previous_rate_{false};
};

}  // namespace navbus::core
