// Horizontal and vertical protection levels of the tightly coupled filter from the GLR fault
// detector's own statistics (seed 000 eqs. 9-15): for every fault hypothesis the detector
// tests (bias steps, pseudorange steps and ramps, rate steps, each from every onset in its
// window), the smallest magnitude it detects with the configured missed-detection probability
// (minimum detectable bias, from the noncentral chi-square of its group statistic), projected
// into the position error through the filter's own closed-loop response. The derivation, the
// references and what the bound does not cover: components/core/doc/protection_levels.md.
//
// The engine feeds it each fused pseudorange epoch (the same numbers it publishes as
// diagnostics for the fault manager) and asks for the levels at each solution with the
// solution's covariance. Pure math; the GLR's storage is allocated once in configure().
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "navbus/core/filter/epoch_diagnostics.hpp"
#include "navbus/core/integrity/glr.hpp"
#include "navbus/core/integrity/protection_level_config.hpp"
#include "navbus/core/math/scratch.hpp"

namespace navbus::core {

/// The largest position errors a just-undetectable fault leaves, over every hypothesis and
/// onset of the latest epoch (doc eq. PL3) [m].
struct FaultBiases {
  double horizontal_m{0.0};
  double vertical_m{0.0};
};

/// sqrt(lambda) at which a group statistic 2 l of `dof` degrees of freedom exceeds 2h with
/// probability 1 - P_md (doc eq. PL2): the minimum detectable magnitude in standard errors of
/// its estimate.
double minimumDetectableSigmas(int dof, double threshold, double missed_detection_probability);

class GlrProtectionLevel {
 public:
  GlrProtectionLevel();
  /// Derives the multipliers: the noncentrality a group's statistic needs to exceed 2h with
  /// probability 1 - P_md, and the Gaussian factors of the two risks.
  void configure(const IntegrityConfig& config);
  /// Forgets the fault hypotheses (the filter restarted).
  void reset();

  /// One fused pseudorange epoch of the filter (after its update); ignored unless enabled.
  /// Recomputes the largest position bias of a just-undetectable fault over every hypothesis and
  /// onset.
  void onEpoch(std::int64_t time_ns, const EpochDiagnostics& epoch);

  /// The levels for a solution whose position error covariance is `pos_cov_ned` [m^2, N E D],
  /// with the fault biases of the latest epoch.
  ProtectionLevels levels(const Eigen::Matrix3d& pos_cov_ned) const;

  const IntegrityConfig& config() const { return config_; }
  const FaultBiases& faultBiases() const { return biases_; }
  /// The detector's latest epoch declared a fault (l >= h).
  bool detected() const { return monitor_ && monitor_->last().valid && monitor_->last().detected; }
  std::uint64_t epochs() const { return monitor_ ? monitor_->epochs() : 0; }
  std::uint64_t refused() const { return monitor_ ? monitor_->refused() : 0; }
  /// Epochs at which the detector declared a fault.
  std::uint64_t detections() const { return detections_; }

 private:
  IntegrityConfig config_;
  /// Only with integrity enabled: its window is about 0.4 MB (its signatures 328 KB with one
  /// receiver), copied with every snapshot of the engine the filter's recovery history takes.
  std::optional<GlrMonitor> monitor_;
  /// Working buffers of onEpoch, rebuilt every epoch (not in copies: math/scratch.hpp).
  Scratch<GlrEpoch> epoch_;
  Scratch<std::vector<GlrMonitor::PositionSignature>> signatures_;
  void reserveSignatures();
  double detectable_sigmas_{0.0};     ///< sqrt(lambda_md) of a one-direction group
  double k_ff_h_{0.0}, k_ff_v_{0.0};  ///< fault-free multipliers of sigma_major and sigma_D
  double k_md_h_{0.0}, k_md_v_{0.0};  ///< the same at the missed-detection probability
  bool have_biases_{false};
  std::uint64_t detections_{0};
  FaultBiases biases_;  ///< of the latest epoch
};

/// The detector's view of one filter epoch (what bus::toGlrEpoch reads from the diagnostics
/// message, without the message).
void toGlrEpoch(std::int64_t time_ns, const EpochDiagnostics& d, GlrEpoch& out);

}  // namespace navbus::core
