// Fixed-interval Rauch-Tung-Striebel smoothing of the error-state filter, for post-processing
// (`navbus offline --smooth`). The forward filter records, at each record epoch k (every epoch
// with an update, and at least every SmoothingLog::interval), its corrected state, its
// covariance P(k|k), the transition Phi(k, k-1) from the previous record, the predicted
// covariance P(k|k-1) before the updates at k, and the error estimate fed back at k. The
// backward pass is Rauch, Tung & Striebel's (AIAA Journal 3(8), 1965) in the closed-loop error
// state, where the forward estimate after each feedback is 0:
//   A(k)    = P(k|k) Phi(k+1, k)^T P(k+1|k)^-1                    (the smoother gain)
//   e(k|N)  = A(k) (e(k+1|N) + dx(k+1))                            (the smoothed error)
//   P(k|N)  = P(k|k) + A(k) (P(k+1|N) - P(k+1|k)) A(k)^T           (its covariance)
// e(k|N) is the smoothed error (estimate minus truth) of the forward state at k; dx(k+1) the
// correction the forward filter applied at k+1 (its prior at k+1 was that much further from
// truth than its posterior). A change of the covariance outside propagation and updates (the
// multi-dimensional filter's inflations at its stage changes, a state replaced by a fresh one)
// is a jump of the model between two records: added variance is process noise, a replaced
// state a zero row of Phi, and the forward filter records the predicted covariance after it
// (IntegratedFilter, "covariance jumps"); a jump between two updates of one epoch splits that
// epoch into two records of the same time. Where the forward filter restarted, re-initialised,
// suspended its covariance or reset it in a way no such model gives, nothing is smoothed
// across: the backward pass starts again.
#pragma once

#include <cstdint>
#include <vector>

#include "navbus/core/filter/error_state.hpp"
#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

/// What the forward filter knew at one record epoch.
struct SmoothingRecord {
  std::int64_t time_ns{0};
  NavState state;                   ///< after the updates at time_ns
  Eigen::Vector3d accel_bias_mps2;  ///< [m/s^2, body]
  Eigen::Vector3d gyro_bias_radps;  ///< [rad/s, body]
  StateMatrix covariance;           ///< P(k|k)
  StateMatrix predicted;            ///< P(k|k-1): before the updates at time_ns
  StateMatrix transition;           ///< Phi(k, k-1) from the previous record
  StateVector correction;           ///< the error estimates fed back at time_ns, summed
  StateMask active;                 ///< the states the filter estimated over (k-1, k]
  /// False when the filter (re)started, re-initialised or did not propagate its covariance
  /// since the previous record: no smoothing across.
  bool continues{false};
};

/// The forward pass's records in time order (two records may share a time: a covariance jump
/// between updates). A filter restored to an earlier snapshot (a rewind that re-processes late
/// data) records again from there: add() drops what the abandoned pass recorded after the
/// record it continues from.
class SmoothingLog {
 public:
  /// The longest time between two records [ns] (records at every update in any case).
  explicit SmoothingLog(std::int64_t interval_ns = 100'000'000) : interval_ns_(interval_ns) {}
  std::int64_t interval() const { return interval_ns_; }
  /// Appends r after dropping every record after the first `kept` (the records r's pass
  /// continues from: records().size() when its previous record was added; -1: a filter that
  /// starts afresh, which drops those at or after r's time).
  void add(const SmoothingRecord& r, std::int64_t kept);
  const std::vector<SmoothingRecord>& records() const { return records_; }
  std::uint64_t dropped() const { return dropped_; }  ///< records of abandoned passes

 private:
  std::int64_t interval_ns_;
  std::vector<SmoothingRecord> records_;
  std::uint64_t dropped_{0};
};

struct SmoothedEpoch {
  std::int64_t time_ns{0};
  NavState state;
  Eigen::Vector3d accel_bias_mps2;
  Eigen::Vector3d gyro_bias_radps;
  StateVector sigma;     ///< smoothed 1-sigma of every state (layout units)
  bool smoothed{false};  ///< false: the last record of a run, the forward estimate as it was
};

/// The backward pass over the records; one smoothed epoch per record time (of records that
/// share a time, the last: the epoch after all its updates). The count of records
/// whose gain could not be formed (P(k+1|k) not positive definite) goes to *singular.
std::vector<SmoothedEpoch> smoothFixedInterval(const std::vector<SmoothingRecord>& records,
                                               std::uint64_t* singular = nullptr);

}  // namespace navbus::core
