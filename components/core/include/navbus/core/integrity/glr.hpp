// Generalized likelihood ratio fault detection and isolation for the tightly coupled filter
// (seed 000 eqs. 6-16, after Willsky and Jones 1976), as an independent monitor of a running
// filter: it needs only what the filter publishes per measurement epoch (innovations eps,
// their covariance V, H, the gain K actually applied, and the transition Phi since the
// previous epoch), see doc/glr_closed_loop.md for the signature recursions of navbus's
// feedback filter.
//
// Hypotheses (one scalar magnitude each, the "directions" T of eq. 16):
//   - a step in each accelerometer and gyro bias (state faults, eq. 7) [m/s^2, rad/s];
//   - per satellite, a step [m] and a ramp [m/s] in its pseudorange and a step in its
//     pseudorange rate [m/s] (measurement faults, eq. 8).
// Positive magnitudes are what the sensor adds: an accelerometer reading high, a pseudorange
// reading long. For every hypothesised onset theta in a sliding window of M epochs the monitor
// accumulates f (eq. 9) and R (eq. 10) over groups of directions: the six IMU directions, and
// the three directions of each satellite. The group statistic l = 1/2 f^T R^+ f (eq. 12) with
// the magnitude nu = R^+ f (eq. 11) is compared with h (eq. 13); isolation projects onto single
// directions (eqs. 14-15: f* = T^T f, R* = T^T R T): INS against GNSS first, then which axis or
// which satellite. R is ill-conditioned when two directions have (nearly) the same signature
// (a pseudorange step and ramp one epoch after onset; x-accelerometer and y-gyro in straight
// flight): the group statistic uses a rank-revealing factorization of R scaled to unit
// diagonal and drops directions whose information is within `rank_tolerance` of dependent,
// and isolation reports such directions as ambiguous instead of picking one.
//
// The parts, one concern each: the window of signature sums f and R (glr_window.hpp, eqs. 9-10),
// the statistic of a group (glr_group_fit.hpp, eqs. 11-12), isolation (glr_isolation.hpp,
// eqs. 14-16); this class runs them on each epoch and decides (eq. 13). Fixed-capacity storage,
// allocated once in configure(): update() allocates nothing (but the first update of a copy,
// which sizes its working buffers: math/scratch.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "navbus/core/integrity/glr_types.hpp"
#include "navbus/core/integrity/glr_window.hpp"

namespace navbus::core {

class GlrMonitor {
 public:
  GlrMonitor();
  explicit GlrMonitor(const GlrConfig& config);
  void configure(const GlrConfig& config);
  /// Forgets every onset and the previous epoch (after a gap in the monitored epochs, or when
  /// the filter was reconfigured so that old signatures no longer describe it).
  void reset();

  /// Processes one epoch: the largest statistic and its onset, and, when it reaches h, the
  /// isolation at that onset (eqs. 14-16; isolationAt() gives it for any onset). Refuses (valid =
  /// false, counted) an epoch with more rows than supported, non-finite values or an innovation
  /// covariance that is not positive definite.
  const GlrResult& update(const GlrEpoch& epoch);

  /// A quarantined satellite is still monitored but cannot trigger a detection.
  void setQuarantined(int sv_id, bool quarantined) { window_.setQuarantined(sv_id, quarantined); }
  bool quarantined(int sv_id) const { return window_.quarantined(sv_id); }

  const GlrConfig& config() const { return config_; }
  const GlrResult& last() const { return result_; }
  /// Onsets currently in the window (age 0 = the latest epoch, count - 1 = the oldest).
  int onsetCount() const { return window_.onsetCount(); }
  /// f (eq. 9) and R (eq. 10) of one direction at one onset; r = 0 if unknown.
  struct DirectionSums {
    double f{0.0};
    double r{0.0};
  };
  DirectionSums directionSums(int onset_age, const GlrHypothesis& h) const;
  /// Group statistics l = 1/2 f^T R^+ f at one onset: the six IMU directions, or the three of
  /// one satellite (0 if the satellite is unknown).
  double imuStatistic(int onset_age) const;
  /// Isolation (eqs. 14-16) at the onset of the given age, as update() reports it for the
  /// onset of the largest statistic; `detected` compares that onset's statistic with h.
  GlrResult isolationAt(int onset_age) const;
  /// Age of the onset whose fault began after `onset_time_ns` (GlrResult::onset_time_ns), or
  /// -1 when it has left the window.
  int onsetAge(std::int64_t onset_time_ns) const;
  double satelliteStatistic(int onset_age, int sv_id) const;

  /// What a fault of unit magnitude along one direction, begun at one onset in the window,
  /// does to the position after the latest epoch's update (GlrWindow::PositionSignature).
  using PositionSignature = GlrWindow::PositionSignature;
  /// Every enabled direction at every onset, after update(); `out` is cleared and refilled
  /// (no allocation once its capacity suffices: glr::directions(glrSlotCapacity(config())) x
  /// window). Quarantined
  /// satellites are left out (they cannot raise a detection).
  void positionSignatures(std::vector<PositionSignature>& out) const {
    window_.positionSignatures(out);
  }
  std::uint64_t epochs() const { return epochs_; }
  std::uint64_t refused() const { return refused_; }

 private:
  void evaluate();
  /// The largest group statistic at one onset (the IMU group and every satellite's).
  double onsetStatistic(const GlrWindow::OnsetView& o) const;

  GlrConfig config_;
  GlrWindow window_;
  GlrResult result_;
  std::uint64_t epochs_{0};
  std::uint64_t refused_{0};
};

}  // namespace navbus::core
