#include "navbus/core/filter/adaptive_noise_scale.hpp"

#include <algorithm>

namespace navbus::core {

void NoiseScaleEstimator::configure(const NoiseScaleConfig& config) {
  config_ = config;
  config_.window_epochs = std::clamp(config.window_epochs, 1, kMaxWindow);
  counters_ = {};
  restart();
}

void NoiseScaleEstimator::restart() {
  count_ = 0;
  next_ = 0;
  open_ = {};
  scale_ = config_.enabled ? bounded(1.0) : 1.0;
}

double NoiseScaleEstimator::bounded(double s) const {
  return std::min(std::max(s, config_.floor), config_.ceiling);
}

void NoiseScaleEstimator::addRow(const ScalarUpdateResult& row) {
  if (!config_.enabled || !row.accepted || !(row.innovation_var > 0.0)) return;
  // q = s (nu_w^2 - V_w + 1): the row's (nu^2 - H P- H^T) / r0.
  open_.q_sum += scale_ * (row.innovation * row.innovation - row.innovation_var + 1.0);
  ++open_.rows;
}

void NoiseScaleEstimator::closeEpoch() {
  if (!config_.enabled || open_.rows == 0) return;
  ++counters_.epochs;
  counters_.rows += static_cast<std::uint64_t>(open_.rows);
  counters_.epochs_scaled += scale_ != 1.0 ? 1 : 0;
  counters_.epochs_at_ceiling += scale_ >= config_.ceiling ? 1 : 0;
  counters_.max_scale = std::max(counters_.max_scale, scale_);
  window_[static_cast<std::size_t>(next_)] = open_;
  open_ = {};
  next_ = (next_ + 1) % config_.window_epochs;
  count_ = std::min(count_ + 1, config_.window_epochs);
  if (count_ < config_.window_epochs) return;
  double q_sum = 0.0;
  int rows = 0;
  for (int i = 0; i < count_; ++i) {
    q_sum += window_[static_cast<std::size_t>(i)].q_sum;
    rows += window_[static_cast<std::size_t>(i)].rows;
  }
  scale_ = bounded(q_sum / rows);
}

}  // namespace navbus::core
