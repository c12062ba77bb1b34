#include "navbus/core/integrity/lane_evidence.hpp"

#include <cmath>

#include "navbus/core/math/chi_square.hpp"

namespace navbus::core {

LaneEvidenceTest::LaneEvidenceTest(const LaneEvidenceConfig& config)
    : config_(config), threshold_(0.5 * chiSquareQuantile(config.false_decision_probability, 1)) {}

void LaneEvidenceTest::open(std::int64_t onset_ns,
                            const std::array<LaneBiasEstimate, 2>& reference) {
  open_ = true;
  expired_ = false;
  onset_ns_ = onset_ns;
  reference_ = reference;
  latest_ = 0.0;
}

std::optional<LaneEvidenceDecision> LaneEvidenceTest::update(
    std::int64_t time_ns, const std::array<LaneBiasEstimate, 2>& now) {
  if (!open_) return std::nullopt;
  std::array<double, 2> change{}, variance{}, normalised{};
  for (std::size_t i = 0; i < 2; ++i) {
    change[i] = now[i].bias - reference_[i].bias;  // eq. 1
    variance[i] = now[i].sigma * now[i].sigma + reference_[i].sigma * reference_[i].sigma;
    normalised[i] = change[i] * change[i] / variance[i];
  }
  const double lambda = 0.5 * (normalised[0] - normalised[1]);  // eq. 2
  latest_ = std::abs(lambda);
  const bool bias_moved = latest_ >= threshold_;
  // A lane that fails its own test since the onset (it held at the reference) while the other
  // holds: a lane already failing before the onset says nothing about this fault.
  auto failedSince = [&](std::size_t i) {
    return reference_[i].consistent && !now[i].consistent && now[1 - i].consistent;
  };
  if (bias_moved || failedSince(0) || failedSince(1)) {
    open_ = false;
    const std::size_t k = bias_moved ? (lambda > 0.0 ? 0 : 1) : (failedSince(0) ? 0 : 1);
    return LaneEvidenceDecision{
        static_cast<int>(k),
        bias_moved ? LaneEvidenceKind::kBiasMoved : LaneEvidenceKind::kLaneInconsistent,
        latest_,
        threshold_,
        change[k],
        std::sqrt(variance[k])};
  }
  if (time_ns - onset_ns_ > std::llround(config_.max_wait_s * 1e9)) {
    open_ = false;
    expired_ = true;
  }
  return std::nullopt;
}

}  // namespace navbus::core
