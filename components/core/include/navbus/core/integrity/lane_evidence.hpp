// Which of two candidate instruments has failed, from the filter lanes' own estimates, when the
// parity space cannot say (two parallel units: the same axis of both has the same signature,
// parity_space.md). Each lane integrates one unit and estimates that unit's biases; a step on
// one unit's axis moves that lane's estimate of it, not the other's. With the estimates of the
// candidate axis in the two lanes, b_i(t), and their values at the last solution before the
// onset, b_i(t0), the changes
//
//   d_i = b_i(t) - b_i(t0),   var d_i <= s_i^2 = sigma_i(t)^2 + sigma_i(t0)^2              (1)
//
// (the bound holds for a consistent filter: the two estimates' errors are positively
// correlated) are, under H_i "candidate i has a step of unknown size, the other none",
// d_i ~ N(mu, s_i^2) and d_j ~ N(0, s_j^2). With mu at its maximum-likelihood value d_i, the
// log-likelihood ratio of H_0 against H_1 (the GLR of two single-fault hypotheses, as seed
// 000's isolation eq. 13 compares its candidates) is
//
//   Lambda = (d_0^2 / s_0^2 - d_1^2 / s_1^2) / 2.                                          (2)
//
// Candidate 0 is named when Lambda >= h, candidate 1 when Lambda <= -h. While neither has
// moved, 2 |Lambda| is at most the larger of two chi-square(1) variables, so h is half the
// chi-square(1) quantile of the configured probability of naming a unit on noise alone.
//
// A lane may not learn the step at all (a navigation-grade gyro's bias is barely observable
// within a minute: measured on seed 000's aircraft, the lane with a 10 deg/h step on its x gyro
// moved its estimate by 0.01 deg/h in 50 s) and drift away instead, until its own consistency
// test (consistency_monitor.hpp: the windowed NIS beyond its chi-square bound) fails. The lanes
// share every aiding measurement, so a fault in neither fails both or none: when one candidate's
// lane fails its test at a time after the onset (having held at the reference) while the
// other's holds, the failed one is named (each lane's test has its own false-alarm probability).
//
// A test that has not decided within `max_wait_s` of the onset gives up (the ambiguity stays).
// Pure math.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

namespace navbus::core {

struct LaneEvidenceConfig {
  /// Probability that eq. 2 crosses h at one solution while neither candidate has moved.
  double false_decision_probability{1e-6};
  double max_wait_s{120.0};  ///< [s] from the onset
};

/// One lane's estimate of the candidate instrument's bias at a solution time.
struct LaneBiasEstimate {
  double bias{0.0};       ///< [rad/s or m/s^2, the instrument's axis]
  double sigma{0.0};      ///< its 1-sigma (> 0)
  bool consistent{true};  ///< the lane's own consistency test holds at this time
};

enum class LaneEvidenceKind { kBiasMoved, kLaneInconsistent };

struct LaneEvidenceDecision {
  int candidate{-1};  ///< 0 or 1
  LaneEvidenceKind kind{LaneEvidenceKind::kBiasMoved};
  double statistic{0.0};     ///< |Lambda| (also when the other evidence decided)
  double threshold{0.0};     ///< h
  double bias_change{0.0};   ///< d of the named candidate [its unit]
  double change_sigma{0.0};  ///< s of the named candidate
};

class LaneEvidenceTest {
 public:
  explicit LaneEvidenceTest(const LaneEvidenceConfig& config);

  /// A new question: which of two candidates, from `onset_ns` on; `reference` are the lanes'
  /// estimates at their last solution at or before the onset.
  void open(std::int64_t onset_ns, const std::array<LaneBiasEstimate, 2>& reference);
  /// The lanes' estimates at one solution time after the onset (times in order). A decision
  /// closes the test; so does max_wait_s without one (expired()).
  std::optional<LaneEvidenceDecision> update(std::int64_t time_ns,
                                             const std::array<LaneBiasEstimate, 2>& now);
  bool isOpen() const { return open_; }
  /// The latest test closed without a decision: the wait ran out.
  bool expired() const { return expired_; }
  double threshold() const { return threshold_; }
  /// |Lambda| of the latest update (0 before one).
  double latestStatistic() const { return latest_; }

 private:
  LaneEvidenceConfig config_;
  double threshold_;
  bool open_{false};
  bool expired_{false};
  std::int64_t onset_ns_{0};
  std::array<LaneBiasEstimate, 2> reference_{};
  double latest_{0.0};
};

}  // namespace navbus::core
