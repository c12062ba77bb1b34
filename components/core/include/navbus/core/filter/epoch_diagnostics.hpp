// What a GNSS measurement epoch of a filter over the state layout publishes for an
// independent fault monitor (the GLR of seed 000 eqs. 6-16): innovations, their covariance
// from the prior, H, the gain actually applied and the transition since the previous epoch.
// Shared by the tightly coupled filter and the static receiver filter.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "navbus/core/filter/aiding_measurements.hpp"
#include "navbus/core/ins/ins_error_model.hpp"

namespace navbus::core {

/// Batch form of one epoch from the prior covariance; rows in the filter's order.
struct EpochDiagnostics {
  std::vector<int> sv_ids;         ///< per row
  std::vector<bool> is_rate;       ///< per row
  std::vector<int> receivers;      ///< per row: the fused receiver (0: the first), 0 if none
  std::vector<bool> used;          ///< per row: fused (false: gated, or monitored only)
  Eigen::VectorXd innovation;      ///< predicted minus measured, m rows
  Eigen::MatrixXd innovation_cov;  ///< V = H P- H^T + R, m x m
  Eigen::MatrixXd h;               ///< m x n (n = layout::kSize)
  Eigen::MatrixXd k;  ///< n x m: the gain applied, P- H_u^T V_uu^-1 on the used rows, 0 elsewhere
  StateMatrix phi{StateMatrix::Identity()};  ///< transition accumulated since the previous epoch
  std::vector<double> test_ratio;            ///< per row, from the sequential gated update
};

/// Sets d.k to the gain a sequence of scalar updates applied in total: for the accepted rows a
/// (diagonal R) the batch gain K_a = P- H_a^T V_aa^-1, 0 for the others. Decoupling the other
/// rows in V (identity block) gives it in one solve. Keeps its storage between epochs.
class AppliedGain {
 public:
  /// Before the epoch's updates: H P- (kept for compute()) and d.innovation_cov = H P- H^T
  /// (R still to add), H = d.h. Both over H's support, the columns with a nonzero element (8
  /// to 11 of the layout's 38 states for pseudoranges, more with their error states).
  void prepare(EpochDiagnostics& d, const StateMatrix& prior_P);
  /// After them: d.k from the prepared H P- and the rows the updates accepted (d.used).
  void compute(EpochDiagnostics& d);
  /// The same gain without a solve, from the covariance after the updates:
  /// K_a = P+ H_a^T R_a^-1 for the accepted rows a, with R diagonal (r: each row's variance)
  /// (the information form of the optimal gain; Simon, Optimal State Estimation, 2006,
  /// eq. 3.42), equal to P- H_a^T V_aa^-1 when the updates applied the optimal gain to every
  /// state H reaches. Returns false, with d.k unchanged, when some of those states are not
  /// estimated (a consider state's gain row is 0, and P+ is then not the optimal one) or a
  /// variance is not positive: then compute() gives it.
  bool computeFromPosterior(EpochDiagnostics& d, const StateMatrix& posterior_P,
                            const Eigen::VectorXd& r, const StateMask& estimated) const;

 private:
  /// A row's nonzero columns of H, ascending.
  struct RowSupport {
    std::array<int, layout::kSize> column{};
    int count{0};
  };
  std::vector<RowSupport> row_support_;  ///< per row of the epoch (capacity kept)
  Eigen::MatrixXd hp_;                   ///< H P-, m x n; zero outside the reached columns
  /// The states H reaches through P- (a column of H P- with a nonzero element), ascending: the
  /// gain's other rows are zero.
  std::array<int, layout::kSize> reached_{};
  int n_reached_{0};
  /// The solve's right-hand sides, H P-'s reached columns in the leading ones (m x n, sized
  /// as hp_: storage reused while the epoch's row count stays).
  Eigen::MatrixXd rhs_;
  Eigen::MatrixXd cov_;
  /// Factorized once at construction (of nothing), so that every member is set: a default
  /// LLT leaves its status unset, which GCC reports when a filter is assigned.
  Eigen::LLT<Eigen::MatrixXd> llt_{Eigen::MatrixXd(0, 0)};
};

/// The sources a loosely coupled epoch names in EpochDiagnostics::sv_ids: the fix's north,
/// east and down axes, each with a value row (its position, in the place of a pseudorange) and
/// a rate row (its velocity, in the place of a pseudorange rate). The GLR of the protection
/// levels (glr_protection_level.hpp) then tests per axis a position step and ramp and a
/// velocity step, as it tests a satellite. Not published: the fault manager watches satellites.
inline constexpr std::array<int, 3> kFixAxisSources{1, 2, 3};

/// One GNSS fix as an epoch for the GLR (rows: position N E D, velocity N E D): the two
/// measurements as they stood at the prior state, the prior covariance and the transition since
/// the previous update, and which rows the update accepted. H has no columns on inactive states
/// and K no rows on states the update does not correct (consider states), as the update did.
struct FixEpochInput {
  const VectorMeasurement* position{nullptr};
  const VectorMeasurement* velocity{nullptr};
  const StateMatrix* prior_P{nullptr};
  const StateMatrix* phi{nullptr};
  StateMask active;
  StateMask estimated;
  std::array<bool, 6> used{};
  std::array<double, 6> test_ratio{};  ///< each row's, as the sequential update gave it
};
void fixEpochDiagnostics(const FixEpochInput& in, AppliedGain& gain, EpochDiagnostics& d);

}  // namespace navbus::core
