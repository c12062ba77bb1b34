// Parity-space monitoring of an array of redundant IMUs (parity_space.hpp, parity_glr.hpp): the
// gyro axes of every unit sense one body rotation increment, the accelerometer axes one body
// velocity increment once the lever arms are accounted for, so each kind is an instance of
// Potter and Suman's array (eq. 1 of parity_space.hpp) with H = the units' axes in the body
// frame:
//
//   gyro axis i of unit u:            m = e_i^T C_u_b dtheta_b                           (1)
//   accelerometer axis i of unit u:   m = e_i^T C_u_b (dv_b + (dw/dt x r_u + w x (w x r_u)) dt)
//
// with C_u_b the unit's mounting (body -> unit axes) and r_u its place from the body origin. The
// lever-arm term is removed before the test with w the least-squares rate of all gyros and dw/dt
// its first difference (a rigid body; the same first order as the simulator's).
//
// Real units have different constant biases, which are a constant parity vector, not a fault:
// the monitor first learns the parity mean (the mean least-squares residual o, `reference_samples`
// samples, no tests), then tests m - o, and afterwards tracks o with a time constant (0: frozen)
// while no detection is under way. A slow drift of the biases is followed; a step is not (it is
// detected within the window, long before the reference moves).
//
// After an isolation the caller excludes the instrument (or both of an ambiguous pair): the array
// of that kind is rebuilt without it, and the test goes on while at least four instruments span
// the three axes. Fixed capacity: update() allocates nothing.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navbus/core/ins/imu_array.hpp"
#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/integrity/parity_glr.hpp"
#include "navbus/core/integrity/parity_space.hpp"

namespace navbus::core {

struct ImuArrayParityConfig {
  ParityGlrConfig glr;
  int reference_samples{6000};  ///< samples that learn the parity mean before the first test
  /// Tracking of the parity mean afterwards [samples]; 0 freezes it.
  double reference_time_constant_samples{180000.0};
};

/// A detection in the array of one kind: the instrument named by its unit (index into the
/// units given to make()) and its axis in that unit's frame.
struct ImuArrayDetection {
  ImuInstrument kind{ImuInstrument::kGyro};
  int unit{-1};
  int axis{-1};
  ParityGlrResult glr;    ///< instrument indices are the array's (unit * 3 + axis)
  double magnitude{0.0};  ///< bias [rad/s or m/s^2, the unit's axis]
  double magnitude_sigma{0.0};
  int runner_up_unit{-1};  ///< the instrument that explains the data about as well, or -1
  int runner_up_axis{-1};
  double runner_up_magnitude{0.0};  ///< the bias were it the runner-up's [its axis]
};

class ImuArrayParity {
 public:
  static constexpr int kMaxUnits = parity::kMaxInstruments / 3;

  /// nullopt with `error` naming the unit and the field (or the GLR key) when the array cannot
  /// be monitored: fewer than 2 or more than kMaxUnits units, a mounting that is not a rotation,
  /// a sigma that is not positive, an interval that is not positive.
  static std::optional<ImuArrayParity> make(const std::vector<ImuArrayUnit>& units,
                                            double interval_s, const ImuArrayParityConfig& config,
                                            std::string& error);

  /// One time-aligned increment of every unit (units() of them, in make()'s order, each in its
  /// own axes). Returns the detections of this sample (at most one per kind).
  struct Result {
    bool learning{true};  ///< the parity mean is still being learned: nothing tested
    std::array<std::optional<ImuArrayDetection>, kImuInstrumentKinds> detections{};
    std::array<double, kImuInstrumentKinds> statistic{};  ///< largest l of each kind (0: off)
  };
  const Result& update(const std::array<ImuIncrement, kMaxUnits>& increments);

  /// Takes the instrument out of the array of its kind and restarts that kind's test; false
  /// (and that kind stops testing) when the rest no longer has parity (fewer than four
  /// instruments or not spanning three axes).
  bool exclude(ImuInstrument kind, int unit, int axis);
  /// Forgets every onset of both kinds (a gap in the data); the learned mean is kept.
  void restart();

  int units() const { return static_cast<int>(units_.size()); }
  /// Whether the kind is still tested (enough instruments left).
  bool testing(ImuInstrument kind) const { return channel(kind).glr.has_value(); }
  int instruments(ImuInstrument kind) const;
  double threshold(ImuInstrument kind) const;
  /// Minimum detectable bias of an instrument still in the array [rad/s or m/s^2]; 0 if it
  /// was excluded.
  double minimumDetectableBias(ImuInstrument kind, int unit, int axis) const;
  /// The array's least-squares body rate of the latest sample [rad/s].
  const Eigen::Vector3d& rate_b() const { return rate_b_radps_; }

 private:
  ImuArrayParity(std::vector<ImuArrayUnit> array_units, double interval_s,
                 const ImuArrayParityConfig& config);

  struct Channel {
    std::array<int, parity::kMaxInstruments> instrument{};  ///< array index of each row
    int rows{0};
    std::optional<ParityGlr> glr;
    parity::Measurements reference;  ///< o: the learned parity mean, measurement space
    parity::Measurements m;          ///< this sample's measurements (scratch)
  };
  Channel& channel(ImuInstrument k) { return channels_[static_cast<std::size_t>(k)]; }
  const Channel& channel(ImuInstrument k) const { return channels_[static_cast<std::size_t>(k)]; }
  /// (Re)builds the channel's space from its rows; false (with `error`) when it has no parity
  /// or the GLR configuration is out of range.
  bool build(ImuInstrument kind, std::string& error);
  /// An accelerometer's noise per sample with what the lever-arm term adds (see the .cpp).
  double accelerometerSigma(const ImuArrayUnit& unit, const Eigen::Vector3d& axis_b) const;
  void fillGyro(const std::array<ImuIncrement, kMaxUnits>& increments);
  void fillAccelerometer(const std::array<ImuIncrement, kMaxUnits>& increments);
  /// Learns or tracks the reference and runs the test of one kind.
  void test(ImuInstrument kind);
  std::optional<ImuArrayDetection> detection(ImuInstrument kind) const;

  std::vector<ImuArrayUnit> units_;
  double interval_s_;
  ImuArrayParityConfig config_;
  std::array<Channel, kImuInstrumentKinds> channels_;
  Eigen::Vector3d rate_b_radps_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d previous_rate_b_radps_{Eigen::Vector3d::Zero()};
  bool have_previous_rate_{false};
  std::int64_t samples_{0};
  Result result_;
};

}  // namespace navbus::core
