// The GLR's window of signature sums (seed 000 eqs. 9-10): for every hypothesised onset theta in
// a sliding window of M measurement epochs, the signature of every direction (an IMU bias step,
// a satellite's pseudorange step, ramp and rate step) through navbus's closed-loop filter, and
// the sums f (eq. 9) and R (eq. 10) of the regression of the innovations on them. The
// recursions are derived in doc/glr_closed_loop.md; the statistics and decisions built on the
// sums are in glr_group_fit.hpp, glr_isolation.hpp and glr.hpp.
//
// Fixed-capacity storage, allocated once in configure(): update() allocates nothing (but the
// first update of a copy, which sizes its working buffers: math/scratch.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "navbus/core/integrity/glr_types.hpp"
#include "navbus/core/math/scratch.hpp"

namespace navbus::core {

class GlrWindow {
 public:
  /// f (eq. 9) and R (eq. 10) of one onset, read from the per-onset columns.
  struct OnsetView {
    std::int64_t ramp_start_ns;           ///< epoch theta - 1: the fault began after it
    Eigen::Map<const Eigen::VectorXd> f;  ///< glr::directions(slot capacity) entries
    Eigen::Map<const Eigen::Matrix<double, glr::kImuDirections, glr::kImuDirections>> r_imu;
    const double* r_sat;
    Eigen::Map<const Eigen::Matrix3d> rSat(int slot) const {
      return Eigen::Map<const Eigen::Matrix3d>(r_sat +
                                               glr::kSatDirections * glr::kSatDirections * slot);
    }
  };
  /// A satellite's rows of one kind in an epoch: one per fused receiver that tracks it (a
  /// fault of the satellite enters each of them).
  struct Rows {
    std::array<int, layout::kMaxFusedReceivers> row{};
    int count{0};
    bool any() const { return count > 0; }
    const int* begin() const { return row.data(); }
    const int* end() const { return row.data() + count; }
  };
  /// A satellite's place in f, R and the signatures: its own fault (every receiver's rows of
  /// it) or, with per-receiver hypotheses, one receiver's rows of it.
  struct Slot {
    int sv_id{0};
    std::int64_t receiver{GlrHypothesis::kEveryReceiver};  ///< whose rows (GlrEpoch::receiver)
    std::uint64_t last_seen{0};
    Rows range, rate;            ///< rows this epoch (none if absent)
    Rows prev_range, prev_rate;  ///< rows at the previous epoch
    bool quarantined{false};
  };
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

  /// Sizes the window (config.window onsets, clamped to 1..kMaxWindow) and forgets everything.
  void configure(const GlrConfig& config);
  /// Forgets every onset and the previous epoch; quarantines stay.
  void reset();
  /// Whether the epoch can be processed: sizes, satellites 1..32 with at most one range and one
  /// rate row per fused receiver, H on the support, finite values, and a time after the
  /// previous epoch's.
  bool accepts(const GlrEpoch& e) const;
  /// Processes an epoch that accepts() took: propagates every signature, starts the onset at
  /// this epoch and adds this epoch's terms to f and R. Returns false (nothing changed) when
  /// the innovation covariance is not positive definite.
  bool update(const GlrEpoch& e);

  int window() const { return config_.window; }
  /// Onsets currently in the window (age 0 = the latest epoch, count - 1 = the oldest).
  int onsetCount() const { return onset_count_; }
  OnsetView onset(int age) const;
  int slotsUsed() const { return slots_used_; }
  const Slot& slot(int s) const { return slots_[static_cast<std::size_t>(s)]; }
  /// The slot of a satellite's own fault or (receiver) of one receiver's rows of it, -1 if
  /// there is none.
  int slotOf(int sv_id, std::int64_t receiver = GlrHypothesis::kEveryReceiver) const;
  /// The hypothesis of a slot's direction (kRangeStep, kRangeRamp or kRateStep).
  GlrHypothesis hypothesis(int slot, int direction) const;

  /// A quarantined satellite keeps its slot (its sums go on) across resets.
  void setQuarantined(int sv_id, bool quarantined);
  bool quarantined(int sv_id) const;

  /// Every enabled direction at every onset, after update(); `out` is cleared and refilled
  /// (no allocation once its capacity suffices: glr::directions(glrSlotCapacity(config)) x
  /// window). Quarantined
  /// satellites are left out (they cannot raise a detection).
  void positionSignatures(std::vector<PositionSignature>& out) const;

 private:
  /// The times of an onset; its signatures and sums live in mu_, f_, r_imu_ and r_sat_.
  struct Onset {
    std::int64_t time_ns{0};        ///< epoch theta
    std::int64_t ramp_start_ns{0};  ///< epoch theta - 1: where the hypothesised ramp is 0
  };
  /// Per-onset values of one quantity, indexed by ring position (not age).
  using OnsetArray = Eigen::Array<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, glr::kMaxWindow>;
  /// A block of mu_ / z_: one signature column c for every ring position.
  int firstColumn(int c) const { return c * config_.window; }
  int onsetIndex(int age) const;
  int propagatedColumns() const { return glr::propagated(slots_used_); }

  void assignSlots(const GlrEpoch& e);
  /// The slot of (sv, receiver), claimed if it has none: a free one or one whose satellite has
  /// not been seen for a whole window; -1 when every slot is taken.
  int slotFor(int sv_id, std::int64_t receiver);
  void claimSlot(int slot, int sv_id, std::int64_t receiver);
  /// Whether this epoch's rows come from more than one receiver and the configuration asks
  /// for per-receiver hypotheses.
  bool perReceiverSlots(const GlrEpoch& e) const;
  void prepareEpoch(const GlrEpoch& e);
  /// Adds to the live rows every state this epoch's recursion can make nonzero (see live_).
  void growLive(const GlrEpoch& e);
  void addLive(int state);
  void propagate();
  /// - G D for one signature column c (every onset): the input entered `row` last epoch.
  void subtractInput(int column, int row);
  void startOnset(const GlrEpoch& e);
  /// H, V^-1 H, S and a on this epoch's support: the live states H measures.
  void prepareSupport(const GlrEpoch& e);
  /// Puts the live states `first[0..count)` in the leading rows of mu, the others after them.
  void reorderLive(const std::array<int, glr::kStates>& first, int count);
  double vInv(int i, int j) const;  ///< (V^-1)_ij of this epoch, from l_inv_
  void accumulate();
  void accumulateImu();
  template <int N>  ///< N: the support's size, or Eigen::Dynamic
  void accumulateSatellite(int slot);
  /// Sizes the working buffers for the configured window (a no-op once sized).
  void sizeWorkingBuffers();

  GlrConfig config_;
  std::uint64_t epochs_{0};    ///< epochs processed (a slot's age is counted in them)
  std::vector<Onset> onsets_;  ///< ring buffer, capacity window
  int onset_head_{0};          ///< index of the oldest onset
  int onset_count_{0};
  std::array<Slot, glr::kMaxSlots> slots_{};
  int slots_used_{0};
  int slot_capacity_{glr::kMaxSatellites};  ///< kMaxSlots with per-receiver hypotheses
  std::array<int, 33> slot_of_sv_{};        ///< PRN 1..32 -> slot of its own fault + 1 (0: none)

  // Signatures of every onset in one matrix, so that one product propagates them all: column
  // c (an IMU step or a satellite's range or rate step, see muColumn) of the onset at ring
  // position i is column c * window + i. Sized once in configure(); the product goes into the
  // working buffer mu_next_, then the two are swapped. Only the live rows are kept (row r is
  // state live_[r]): a state that no signature has reached is zero in every column, and stays
  // so as long as B, G and the IMU inputs do not reach it from a live one (growLive checks it
  // every epoch), so the recursion runs on the live states only (the active ones of the filter
  // watched: 17 of 38 for seed 001 tightly coupled).
  using SignatureMatrix = Eigen::Matrix<double, glr::kStates, Eigen::Dynamic>;
  SignatureMatrix mu_;
  std::array<int, glr::kStates> live_{};    ///< state of each live row
  std::array<int, glr::kStates> row_of_{};  ///< live row of each state, -1 if not live
  int live_count_{0};
  /// This epoch's support (the live states H measures): the leading support_count_ live rows.
  int support_count_{0};
  OnsetArray spacing_s_;  ///< t_theta - t_{theta-1} of each ring position [s]
  // Sums of eqs. 9-10, one column per ring position: f per direction, the IMU group's R (6 x 6,
  // column-major) and each satellite slot's R (3 x 3, column-major, slot after slot).
  // Sized for the slot capacity in configure() (a one-receiver filter's window stays small:
  // it is copied into every snapshot of the filter's recovery history).
  Eigen::MatrixXd f_;
  Eigen::Matrix<double, glr::kImuDirections * glr::kImuDirections, Eigen::Dynamic> r_imu_;
  Eigen::MatrixXd r_sat_;

  // What the recursion keeps of epoch k-1, and this epoch's H on its support (positionSignatures
  // reads it after the update).
  bool have_previous_{false};
  std::int64_t time_ns_{0}, prev_time_ns_{0};
  glr::KMatrix prev_k_;
  using SupportVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, glr::kSupport, 1>;
  using SupportMatrix =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, glr::kSupport, glr::kSupport>;
  using HSupport =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, glr::kMaxRows, glr::kSupport>;
  HSupport h_support_;  ///< H on this epoch's support (live row order)
  /// The previous epoch's H on the fixed support (kSupportHead, then kSupportTail)
  Eigen::Matrix<double, Eigen::Dynamic, glr::kSupport, 0, glr::kMaxRows, glr::kSupport>
      prev_h_fixed_;

  /// Working buffers of one update, each written before it is read (not in copies, such as the
  /// recovery history's snapshots of the filter: scratch.hpp; about 100 KB).
  struct Work {
    Eigen::LLT<glr::RowMatrix> llt;  ///< Cholesky factor of this epoch's V
    glr::RowMatrix l_inv;            ///< L^-1 of this epoch's V = L L^T (lower triangular)
    glr::RowVector w;                ///< V^-1 eps
    HSupport u;                      ///< V^-1 H on the support
    SupportMatrix s;                 ///< H^T V^-1 H on the support
    SupportVector a;                 ///< H^T V^-1 eps on the support
    StateMatrix b;                   ///< Phi_k (I - K_{k-1} H_{k-1})
    glr::KMatrix g;                  ///< Phi_k K_{k-1}
    /// B on the live states (the propagation's matrix) and a G column on them
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, glr::kStates, glr::kStates> b_live;
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, glr::kStates, 1> g_live;
    /// The next mu_ and S times mu_'s support rows (z), same column order.
    SignatureMatrix mu_next;
    Eigen::Matrix<double, glr::kSupport, Eigen::Dynamic> z;
  };
  Scratch<Work> work_;
};

}  // namespace navbus::core
