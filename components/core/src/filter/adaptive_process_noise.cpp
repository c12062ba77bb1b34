#include "navbus/core/filter/adaptive_process_noise.hpp"

#include <algorithm>
#include <cmath>

namespace navbus::core {

void ProcessNoiseScaleEstimator::configure(const ProcessNoiseScaleConfig& config) {
  config_ = config;
  counters_ = {};
  restart();
}

void ProcessNoiseScaleEstimator::restart() {
  num_ = den_ = info_ = open_num_ = open_den_ = open_info_ = 0.0;
  open_rows_ = 0;
  last_close_ns_ = 0;
  closed_any_ = false;
  scale_ = config_.enabled ? bounded(1.0) : 1.0;
}

double ProcessNoiseScaleEstimator::bounded(double s) const {
  return std::min(std::max(s, config_.floor), config_.ceiling);
}

void ProcessNoiseScaleEstimator::addRow(const ProcessNoiseRow& row) {
  const double v = row.innovation_var;
  // p <= V - r is where the split holds; a row with no process part tells nothing of Q.
  if (!config_.enabled || !(v > 0.0) || !(row.process_var > 0.0) || !(scale_ > 0.0)) return;
  const double g = row.process_var / scale_;
  const double y = row.innovation * row.innovation - (v - row.process_var);
  open_num_ += g * y / (v * v);
  open_den_ += g * g / (v * v);
  open_info_ += (row.process_var / v) * (row.process_var / v);
  ++open_rows_;
}

void ProcessNoiseScaleEstimator::closeEpoch(std::int64_t time_ns) {
  if (!config_.enabled || open_rows_ == 0) return;
  ++counters_.epochs;
  counters_.rows += static_cast<std::uint64_t>(open_rows_);
  counters_.epochs_scaled += scale_ != 1.0 ? 1 : 0;
  counters_.epochs_at_ceiling += scale_ >= config_.ceiling ? 1 : 0;
  counters_.max_scale = std::max(counters_.max_scale, scale_);
  if (closed_any_) {
    const double dt_s =
        1e-9 * static_cast<double>(std::max<std::int64_t>(time_ns - last_close_ns_, 0));
    const double fade = std::exp(-dt_s / config_.memory_s);
    num_ *= fade;
    den_ *= fade;
    info_ *= fade;
  }
  num_ += open_num_;
  den_ += open_den_;
  info_ += open_info_;
  open_num_ = open_den_ = open_info_ = 0.0;
  open_rows_ = 0;
  last_close_ns_ = time_ns;
  closed_any_ = true;
  // The prior: n0 rows all process noise at the scale in use (weight n0 / alpha^2 in the
  // nominal units of the sums), at the configured Q.
  const double prior = config_.prior_rows / (scale_ * scale_);
  scale_ = bounded((num_ + prior) / (den_ + prior));
}

}  // namespace navbus::core
