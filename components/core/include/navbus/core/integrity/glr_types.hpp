// The GLR monitor's inputs, hypotheses and results (seed 000 eqs. 6-16, glr.hpp): sizes, the
// epoch the monitored filter publishes, the directions T, the configuration and what a test
// reports; shared by the window of signature sums (glr_window.hpp), the group statistics
// (glr_group_fit.hpp), isolation (glr_isolation.hpp) and the monitor that puts them together
// (glr.hpp).
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "navbus/core/gnss/gnss_measurement.hpp"
#include "navbus/core/ins/ins_error_model.hpp"
#include "navbus/core/ins/state_layout.hpp"

namespace navbus::core {

namespace glr {
inline constexpr int kStates = layout::kSize;
inline constexpr int kMaxSatellites = kMaxEpochSatellites;
inline constexpr int kMaxRows = 2 * kMaxSatellites;
/// Satellite slots: one per satellite (its own fault, in every fused receiver's rows) and, with
/// several fused receivers and GlrConfig::per_receiver_satellites, one per satellite a receiver
/// tracks (a fault in that receiver's rows only: multipath, a spoofed channel). A stacked epoch
/// holds at most kMaxSatellites receiver-satellite observations.
inline constexpr int kMaxSlots = 2 * kMaxSatellites;
inline constexpr int kImuDirections = 6;  ///< accelerometer x y z, gyro x y z
inline constexpr int kSatDirections = 3;  ///< pseudorange step, pseudorange ramp, rate step
/// Directions and propagated signature columns with `slots` satellite slots: the IMU steps and
/// each slot's three directions; propagated, each slot's pseudorange and rate steps (ramps are
/// sums of steps, see glr_window.cpp).
constexpr int directions(int slots) {
  return kImuDirections + kSatDirections * slots;
}
constexpr int propagated(int slots) {
  return kImuDirections + 2 * slots;
}
inline constexpr int kMaxWindow = 100;  ///< largest configurable window M [epochs]
/// The states pseudorange and rate rows measure: position, velocity and attitude (the first
/// nine; attitude through the antenna's lever arm, gnss_measurement.hpp), the clock bias and
/// drift, the satellites' time-correlated pseudorange errors and a second receiver's clock
/// (the trailing ones, when the filter models them). f and R see a signature only through H, so
/// they are accumulated on these states; an epoch whose H reaches others is refused.
inline constexpr StateBlock kSupportHead{layout::kPos.index,
                                         layout::kPos.dof + layout::kVel.dof + layout::kAtt.dof};
inline constexpr StateBlock kSupportTail{layout::kClockBias.index,
                                         layout::kSize - layout::kClockBias.index};
inline constexpr int kSupport = kSupportHead.dof + kSupportTail.dof;
static_assert(kSupportHead.index == 0 && layout::kVel.index == layout::kPos.end() &&
                  layout::kAtt.index == layout::kVel.end() &&
                  layout::kClockDrift.index == layout::kClockBias.end() &&
                  layout::kPseudorangeError.index == layout::kClockDrift.end() &&
                  kSupportTail.end() == kStates,
              "the GLR's support is position, velocity, attitude (leading) and the receiver's "
              "clock and pseudorange errors (trailing)");

using RowVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxRows, 1>;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxRows, kMaxRows>;
using HMatrix = Eigen::Matrix<double, Eigen::Dynamic, kStates, Eigen::RowMajor, kMaxRows, kStates>;
using KMatrix = Eigen::Matrix<double, kStates, Eigen::Dynamic, 0, kStates, kMaxRows>;
/// A satellite's directions, in this order among its three entries of f and in its 3 x 3 R.
inline constexpr int kRangeStep = 0;
inline constexpr int kRangeRamp = 1;
inline constexpr int kRateStep = 2;
/// Index of a satellite slot's direction in f: the six IMU directions, then three per slot.
constexpr int satColumn(int slot, int direction) {
  return kImuDirections + kSatDirections * slot + direction;
}
}  // namespace glr

enum class GlrFault { kAccelStep, kGyroStep, kRangeStep, kRangeRamp, kRateStep };

/// One direction T: what is faulty and how.
struct GlrHypothesis {
  /// receiver: the fault is in every fused receiver's measurements of the satellite.
  static constexpr std::int64_t kEveryReceiver = -1;
  GlrFault fault{GlrFault::kAccelStep};
  int axis{0};   ///< body axis 0..2 for IMU faults
  int sv_id{0};  ///< satellite for measurement faults
  /// For measurement faults: the one receiver (GlrEpoch::receiver) whose measurements of sv_id
  /// are faulty, or kEveryReceiver (the satellite's own fault).
  std::int64_t receiver{kEveryReceiver};
  bool isImu() const { return fault == GlrFault::kAccelStep || fault == GlrFault::kGyroStep; }
};

struct GlrConfig {
  int window{20};  ///< M: hypothesised onsets kept [measurement epochs]
  /// h: a fault is declared when l = 1/2 f^T R^+ f >= h for some group and onset (eq. 13).
  double threshold{35.718};
  /// Isolation: a runner-up direction whose statistic is within this many units of log-
  /// likelihood of the best one explains the data about as well (likelihood ratio e^margin):
  /// the decision names both.
  double ambiguity_margin{2.0};
  /// Isolation: an IMU direction whose signature correlates with the best one's at least this
  /// much (|R_ab| / sqrt(R_aa R_bb)) cannot be told apart from it with the data at hand
  /// (x-accelerometer and y-gyro in straight flight): the decision names both.
  double ambiguity_correlation{0.95};
  /// Directions whose share of information, after scaling R to unit diagonal, falls below
  /// this are treated as dependent on the others (rank-revealing factorization).
  double rank_tolerance{1e-6};
  bool imu_steps{true};
  bool range_steps{true};
  bool range_ramps{true};
  bool rate_steps{true};
  /// With several fused receivers: beside each satellite's own fault, a fault in one receiver's
  /// measurements of it (each direction above per receiver-satellite pair). Without it a
  /// one-receiver error is fitted by the satellite's every-receiver directions or an IMU one.
  /// Doubles the satellite slots the window is sized for (memory and cost of a fused filter).
  bool per_receiver_satellites{false};
};

/// Satellite slots a window of this configuration holds.
constexpr int glrSlotCapacity(const GlrConfig& config) {
  return config.per_receiver_satellites ? glr::kMaxSlots : glr::kMaxSatellites;
}

/// One measurement epoch of the monitored filter, SI units, rows in the filter's order.
struct GlrEpoch {
  std::int64_t time_ns{0};
  int rows{0};
  std::array<int, glr::kMaxRows> sv_id{};
  std::array<bool, glr::kMaxRows> is_rate{};  ///< false: pseudorange row
  /// The receiver of each row (any key: the filter's receiver index, a receiver id); rows of
  /// one satellite with different keys are different receivers' measurements of it.
  std::array<std::int64_t, glr::kMaxRows> receiver{};
  glr::RowVector innovation;      ///< eps = predicted - measured [m, m/s]
  glr::RowMatrix innovation_cov;  ///< V = H P- H^T + R
  glr::HMatrix h;                 ///< rows x n
  glr::KMatrix k;                 ///< n x rows: the gain applied (0 columns for unused rows)
  StateMatrix phi{StateMatrix::Identity()};  ///< transition from the previous epoch to this one
};

struct GlrCandidate {
  GlrHypothesis hypothesis;
  double statistic{0.0};        ///< l* = 1/2 f*^2 / R* (eqs. 14-15 with T this direction)
  double magnitude{0.0};        ///< nu* = f* / R* [m/s^2, rad/s, m or m/s]
  double magnitude_sigma{0.0};  ///< standard error of nu*: 1 / sqrt(R*)
};

enum class GlrSourceClass { kNone, kImu, kSatellite };

struct GlrResult {
  bool valid{false};              ///< false: the epoch was refused (see GlrMonitor::refused())
  bool detected{false};           ///< statistic >= threshold
  double statistic{0.0};          ///< largest group statistic l over onsets and groups
  double threshold{0.0};          ///< h
  int onset_epochs_ago{0};        ///< theta of the largest statistic: 0 = this epoch
  std::int64_t onset_time_ns{0};  ///< the fault began after this time (epoch theta - 1)
  // Isolation (eqs. 14-16), from here on: filled by update() only when detected (it is what
  // the paper does at detection time); GlrMonitor::isolationAt() gives it for any onset.
  GlrSourceClass source{GlrSourceClass::kNone};
  double imu_statistic{0.0};        ///< IMU group l at the onset
  double satellite_statistic{0.0};  ///< best satellite group l at the onset
  double imu_significance{0.0};     ///< -log10 P(chi2(rank) >= 2 l) of the IMU group
  double satellite_significance{0.0};
  int imu_rank{0};
  int satellite_rank{0};
  int candidate_count{0};  ///< directions in `candidates` (best first, same class)
  std::array<GlrCandidate, 3> candidates{};
  bool ambiguous{false};  ///< candidates[1] explains the data about as well as [0]
  /// The onset is the oldest of a full window: the fault may have begun earlier, and the
  /// signatures from this onset on do not describe what came before (isolation uncertain).
  bool onset_censored{false};
  double correlation{0.0};  ///< of the signatures of candidates [0] and [1], -1..1
};

/// Name of a hypothesis for logs and messages, e.g. "accelerometer x step", "sv 13 range ramp".
const char* glrFaultName(GlrFault fault);

}  // namespace navbus::core
