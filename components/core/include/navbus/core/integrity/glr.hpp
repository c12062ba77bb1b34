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
// Fixed-capacity storage, allocated once in configure(): update() allocates nothing (but the
// first update of a copy, which sizes its working buffers: math/scratch.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "navbus/core/gnss/gnss_measurement.hpp"
#include "navbus/core/ins/ins_error_model.hpp"
#include "navbus/core/ins/state_layout.hpp"
#include "navbus/core/math/scratch.hpp"

namespace navbus::core {

namespace glr {
inline constexpr int kStates = layout::kSize;
inline constexpr int kMaxSatellites = kMaxEpochSatellites;
inline constexpr int kMaxRows = 2 * kMaxSatellites;
inline constexpr int kImuDirections = 6;  ///< accelerometer x y z, gyro x y z
inline constexpr int kSatDirections = 3;  ///< pseudorange step, pseudorange ramp, rate step
inline constexpr int kMaxDirections = kImuDirections + kSatDirections * kMaxSatellites;
/// Signature columns propagated: the IMU steps and each satellite's pseudorange and rate steps
/// (ramps are sums of steps, see glr.cpp).
inline constexpr int kMaxPropagated = kImuDirections + 2 * kMaxSatellites;
inline constexpr int kMaxWindow = 100;  ///< largest configurable window M [epochs]
/// The states pseudorange and rate rows measure: position, velocity and attitude (the first
/// nine; attitude through the antenna's lever arm, gnss_measurement.hpp), the clock bias and
/// drift and the satellites' time-correlated pseudorange errors (the trailing ones, when the
/// filter models them). f and R see a signature only through H, so they are accumulated on
/// these states; an epoch whose H reaches others is refused.
inline constexpr StateBlock kSupportHead{layout::kPos.index,
                                         layout::kPos.dof + layout::kVel.dof + layout::kAtt.dof};
inline constexpr StateBlock kSupportTail{
    layout::kClockBias.index,
    layout::kClockBias.dof + layout::kClockDrift.dof + layout::kPseudorangeError.dof};
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
using DirectionVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxDirections, 1>;
}  // namespace glr

enum class GlrFault { kAccelStep, kGyroStep, kRangeStep, kRangeRamp, kRateStep };

/// One direction T: what is faulty and how.
struct GlrHypothesis {
  GlrFault fault{GlrFault::kAccelStep};
  int axis{0};   ///< body axis 0..2 for IMU faults
  int sv_id{0};  ///< satellite for measurement faults
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
};

/// One measurement epoch of the monitored filter, SI units, rows in the filter's order.
struct GlrEpoch {
  std::int64_t time_ns{0};
  int rows{0};
  std::array<int, glr::kMaxRows> sv_id{};
  std::array<bool, glr::kMaxRows> is_rate{};  ///< false: pseudorange row
  glr::RowVector innovation;                  ///< eps = predicted - measured [m, m/s]
  glr::RowMatrix innovation_cov;              ///< V = H P- H^T + R
  glr::HMatrix h;                             ///< rows x n
  glr::KMatrix k;  ///< n x rows: the gain applied (0 columns for unused rows)
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
  void setQuarantined(int sv_id, bool quarantined);
  bool quarantined(int sv_id) const;

  const GlrConfig& config() const { return config_; }
  const GlrResult& last() const { return result_; }
  /// Onsets currently in the window (age 0 = the latest epoch, count - 1 = the oldest).
  int onsetCount() const { return onset_count_; }
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
  /// does to the position after the latest epoch's update, with what the test knows of it.
  struct PositionSignature {
    GlrHypothesis hypothesis;
    int onset_age{0};
    /// mu+ = mu - K rho (doc eqs. C1, C3) on the position error states [m per unit of the
    /// fault's magnitude, N E D]
    Eigen::Vector3d position_ned{Eigen::Vector3d::Zero()};
    /// R* = T^T R T (eqs. 10, 14): under this fault of magnitude nu, 2 l of its group is
    /// noncentral chi-square with noncentrality nu^2 R*.
    double information{0.0};
  };
  /// Every enabled direction at every onset, after update(); `out` is cleared and refilled
  /// (no allocation once its capacity suffices: kMaxDirections * window). Quarantined
  /// satellites are left out (they cannot raise a detection).
  void positionSignatures(std::vector<PositionSignature>& out) const;
  std::uint64_t epochs() const { return epochs_; }
  std::uint64_t refused() const { return refused_; }

 private:
  /// The times of an onset; its signatures and sums live in mu_, f_, r_imu_ and r_sat_.
  struct Onset {
    std::int64_t time_ns{0};        ///< epoch theta
    std::int64_t ramp_start_ns{0};  ///< epoch theta - 1: where the hypothesised ramp is 0
  };
  /// f (eq. 9) and R (eq. 10) of one onset, read from the per-onset columns.
  struct OnsetView {
    std::int64_t ramp_start_ns;
    Eigen::Map<const Eigen::Matrix<double, glr::kMaxDirections, 1>> f;
    Eigen::Map<const Eigen::Matrix<double, glr::kImuDirections, glr::kImuDirections>> r_imu;
    const double* r_sat;
    Eigen::Map<const Eigen::Matrix3d> rSat(int slot) const {
      return Eigen::Map<const Eigen::Matrix3d>(r_sat +
                                               glr::kSatDirections * glr::kSatDirections * slot);
    }
  };
  struct Slot {
    int sv_id{0};
    std::uint64_t last_seen{0};
    int range_row{-1}, rate_row{-1};            ///< rows this epoch, -1 if absent
    int prev_range_row{-1}, prev_rate_row{-1};  ///< rows at the previous epoch
    bool quarantined{false};
  };
  /// Per-onset values of one quantity, indexed by ring position (not age).
  using OnsetArray = Eigen::Array<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, glr::kMaxWindow>;
  /// A block of mu_ / ms_ / z_: one signature column c for every ring position.
  int firstColumn(int c) const { return c * config_.window; }

  bool validate(const GlrEpoch& e) const;
  void assignSlots(const GlrEpoch& e);
  void claimSlot(int slot, int sv_id);
  void prepareEpoch(const GlrEpoch& e);
  double vInv(int i, int j) const;  ///< (V^-1)_ij of this epoch, from l_inv_
  bool biasAndClockRowsSparse() const;
  void propagate();
  void startOnset(const GlrEpoch& e);
  void accumulate();
  void accumulateImu();
  void accumulateSatellite(int slot);
  int onsetIndex(int age) const;
  void evaluate();
  OnsetView onset(int age) const;
  void isolate(const OnsetView& o, int onset_age, GlrResult& r) const;
  double onsetStatistic(const OnsetView& o) const;
  int propagatedColumns() const { return glr::kImuDirections + 2 * slots_used_; }
  /// Sizes the working buffers for the configured window (a no-op once sized).
  void sizeWorkingBuffers();

  GlrConfig config_;
  std::vector<Onset> onsets_;  ///< ring buffer, capacity window
  int onset_head_{0};          ///< index of the oldest onset
  int onset_count_{0};
  std::array<Slot, glr::kMaxSatellites> slots_{};
  int slots_used_{0};
  std::array<int, 33> slot_of_sv_{};  ///< PRN 1..32 -> slot + 1 (0: none)

  // Signatures of every onset in one matrix, so that one product propagates them all: column
  // c (an IMU step or a satellite's range or rate step, see muColumn) of the onset at ring
  // position i is column c * window + i. Sized once in configure(); the product goes into the
  // working buffer mu_next_, then the two are swapped.
  using SignatureMatrix = Eigen::Matrix<double, glr::kStates, Eigen::Dynamic>;
  SignatureMatrix mu_;
  /// Working buffers, overwritten by every update before they are read (not in copies:
  /// scratch.hpp): the next mu_, mu_ on H's support (ms_) and S ms_ (z_), same column order.
  Scratch<SignatureMatrix> mu_next_;
  Scratch<Eigen::Matrix<double, glr::kSupport, Eigen::Dynamic>> ms_, z_;
  OnsetArray spacing_s_;  ///< t_theta - t_{theta-1} of each ring position [s]
  // Sums of eqs. 9-10, one column per ring position: f per direction, the IMU group's R (6 x 6,
  // column-major) and each satellite slot's R (3 x 3, column-major, slot after slot).
  Eigen::Matrix<double, glr::kMaxDirections, Eigen::Dynamic> f_;
  Eigen::Matrix<double, glr::kImuDirections * glr::kImuDirections, Eigen::Dynamic> r_imu_;
  Eigen::Matrix<double, glr::kSatDirections * glr::kSatDirections * glr::kMaxSatellites,
                Eigen::Dynamic>
      r_sat_;

  // Per-epoch quantities (current epoch k) and what the recursion keeps of epoch k-1.
  bool have_previous_{false};
  std::int64_t time_ns_{0}, prev_time_ns_{0};
  Eigen::LLT<glr::RowMatrix> llt_;  ///< Cholesky factor of this epoch's V
  glr::KMatrix prev_k_;
  glr::RowMatrix l_inv_;  ///< L^-1 of this epoch's V = L L^T (lower triangular)
  glr::RowVector w_;      ///< V^-1 eps
  using SupportVector = Eigen::Matrix<double, glr::kSupport, 1>;
  using SupportMatrix = Eigen::Matrix<double, glr::kSupport, glr::kSupport>;
  Eigen::Matrix<double, Eigen::Dynamic, glr::kSupport, 0, glr::kMaxRows, glr::kSupport> h_support_,
      u_,               ///< H and V^-1 H on the support
      prev_h_support_;  ///< the previous epoch's H on the support
  SupportMatrix s_;     ///< H^T V^-1 H on the support
  SupportVector a_;     ///< H^T V^-1 eps on the support
  StateMatrix b_;       ///< Phi_k (I - K_{k-1} H_{k-1})
  glr::KMatrix g_;      ///< Phi_k K_{k-1}

  GlrResult result_;
  std::uint64_t epochs_{0};
  std::uint64_t refused_{0};
};

/// Name of a hypothesis for logs and messages, e.g. "accelerometer x step", "sv 13 range ramp".
const char* glrFaultName(GlrFault fault);

}  // namespace navbus::core
