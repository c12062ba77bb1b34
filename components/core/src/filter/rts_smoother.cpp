#include "navbus/core/filter/rts_smoother.hpp"

#include <algorithm>

#include <Eigen/Cholesky>

namespace navbus::core {

void SmoothingLog::add(const SmoothingRecord& r, std::int64_t kept) {
  // Kept: the records up to the one r continues from, or (a filter that starts afresh) those
  // before r.
  const auto keep_end =
      kept >= 0 ? records_.begin() +
                      std::min<std::ptrdiff_t>(kept, static_cast<std::ptrdiff_t>(records_.size()))
                : std::lower_bound(
                      records_.begin(), records_.end(), r.time_ns,
                      [](const SmoothingRecord& x, std::int64_t t) { return x.time_ns < t; });
  dropped_ += static_cast<std::uint64_t>(records_.end() - keep_end);
  records_.erase(keep_end, records_.end());
  records_.push_back(r);
}

namespace {

/// Phi and P(k+1|k) restricted to the states active over the interval: an inactive state is
/// not driven and drives nothing (error_state.hpp), so its rows and columns are the identity's.
void restrictToActive(const StateMask& active, StateMatrix& phi, StateMatrix& predicted,
                      StateMatrix& covariance) {
  for (int i = 0; i < layout::kSize; ++i) {
    if (active[static_cast<std::size_t>(i)]) continue;
    phi.row(i).setZero();
    phi.col(i).setZero();
    phi(i, i) = 1.0;
    const double pred = predicted(i, i), cov = covariance(i, i);
    predicted.row(i).setZero();
    predicted.col(i).setZero();
    covariance.row(i).setZero();
    covariance.col(i).setZero();
    predicted(i, i) = pred > 0.0 ? pred : 1.0;
    covariance(i, i) = cov > 0.0 ? cov : 1.0;
  }
}

SmoothedEpoch forwardOnly(const SmoothingRecord& r) {
  return {r.time_ns,
          r.state,
          r.accel_bias_mps2,
          r.gyro_bias_radps,
          r.covariance.diagonal().cwiseMax(0.0).cwiseSqrt(),
          false};
}

SmoothedEpoch corrected(const SmoothingRecord& r, const StateVector& error,
                        const StateMatrix& covariance) {
  return {r.time_ns,
          correctedState(r.state, error),
          r.accel_bias_mps2 - error.segment<3>(layout::kAccelBias.index),
          r.gyro_bias_radps - error.segment<3>(layout::kGyroBias.index),
          covariance.diagonal().cwiseMax(0.0).cwiseSqrt(),
          true};
}

}  // namespace

std::vector<SmoothedEpoch> smoothFixedInterval(const std::vector<SmoothingRecord>& records,
                                               std::uint64_t* singular) {
  std::vector<SmoothedEpoch> out(records.size());
  if (records.empty()) return out;
  std::uint64_t failed = 0;
  // At the last record of a run the smoothed estimate is the forward one.
  StateVector error = StateVector::Zero();
  StateMatrix smoothed_cov = records.back().covariance;
  out.back() = forwardOnly(records.back());
  for (std::size_t k = records.size() - 1; k-- > 0;) {
    const SmoothingRecord& now = records[k];
    const SmoothingRecord& next = records[k + 1];
    StateMatrix phi = next.transition, predicted = next.predicted, covariance = now.covariance;
    restrictToActive(next.active & now.active, phi, predicted, covariance);
    const Eigen::LLT<StateMatrix> llt(predicted);
    if (!next.continues || llt.info() != Eigen::Success) {
      failed += next.continues ? 1 : 0;
      error.setZero();
      smoothed_cov = now.covariance;
      out[k] = forwardOnly(now);
      continue;
    }
    // A = P(k|k) Phi^T P(k+1|k)^-1, from P(k+1|k) A^T = Phi P(k|k) (both symmetric).
    const StateMatrix gain = llt.solve(phi * covariance).transpose();
    error = gain * (error + next.correction);
    smoothed_cov = covariance + gain * (smoothed_cov - predicted) * gain.transpose();
    smoothed_cov = (0.5 * (smoothed_cov + smoothed_cov.transpose())).eval();
    out[k] = corrected(now, error, smoothed_cov);
  }
  if (singular != nullptr) *singular = failed;
  // One epoch per time: a jump between two updates of an epoch recorded it twice.
  const auto same_time = [](const SmoothedEpoch& a, const SmoothedEpoch& b) {
    return a.time_ns == b.time_ns;
  };
  std::reverse(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end(), same_time), out.end());
  std::reverse(out.begin(), out.end());
  return out;
}

}  // namespace navbus::core
