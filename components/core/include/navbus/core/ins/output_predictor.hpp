// The low-latency output: the latest solution of the deterministic filter, propagated with
// every inertial increment as it arrives (the output predictor of PX4's EKF2, which runs its
// filter on a delayed time horizon and predicts forward at IMU rate; here the delay is what
// the ordered merge waits for, see docs/bus.md, the low-latency output).
//
// Definition, so that any output can be reproduced from the bus alone: an output at increment
// time t_k is the anchor (the newest deterministic solution at time t_j <= t_k the predictor
// was given) mechanized by a strapdown started at the anchor (no coning partner for its first
// increment) through every accepted increment in (t_j, t_k], each corrected by the anchor's
// accelerometer and gyro biases (increment - bias * interval). The same sequence of anchors
// and increments gives the same outputs bit for bit. Measurement updates after t_j are not in
// it: it drifts from the deterministic solution as free inertial navigation does, for as long
// as the filter lags the newest increment.
#pragma once

#include <cstdint>
#include <optional>

#include <Eigen/Core>

#include "navbus/core/ins/imu_correction.hpp"
#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/math/ring_buffer.hpp"

namespace navbus::core {

/// The deterministic solution an output is propagated from.
struct OutputAnchor {
  NavState state;            ///< at state.time_ns
  ImuCorrection correction;  ///< removed from increments
};

struct OutputPredictorCounters {
  std::uint64_t outputs{0};
  std::uint64_t before_anchor{0};       ///< increments not after the anchor: already in it
  std::uint64_t not_after_previous{0};  ///< increments not after the previous one (out of order)
  std::uint64_t gaps{0};                ///< increments whose interval does not start at the output
  std::uint64_t overflow{0};            ///< increments dropped because the buffer was full
};

class OutputPredictor {
 public:
  /// `max_buffered`: increments kept while the filter lags (newer than the anchor).
  OutputPredictor(earth::GravityModel gravity, std::size_t max_buffered);

  /// A new deterministic solution: the output is re-propagated from it through the buffered
  /// increments after it (older ones are dropped).
  void setAnchor(const OutputAnchor& anchor);
  /// An increment as it arrives; the propagated state if there is an anchor and the increment
  /// continues the output (a gap or an out-of-order increment gives none and is counted).
  std::optional<NavState> addIncrement(const ImuIncrement& inc);
  /// Forgets the anchor and the buffer (a new run of the filter).
  void reset();

  /// Time of the anchor of the current output [ns, GPS] (-1: none).
  std::int64_t anchorTime() const { return anchor_ ? anchor_->state.time_ns : -1; }
  const OutputPredictorCounters& counters() const { return counters_; }

 private:
  /// Mechanizes one increment from the current output; false across a gap.
  bool step(const ImuIncrement& inc);
  void repropagate();

  earth::GravityModel gravity_;
  std::size_t max_buffered_;
  std::optional<OutputAnchor> anchor_;
  RingBuffer<ImuIncrement> buffered_;  ///< accepted increments after the anchor, in time order
  StrapdownNed ins_;
  bool continuous_{false};  ///< the output has integrated every buffered increment
  OutputPredictorCounters counters_;
};

}  // namespace navbus::core
