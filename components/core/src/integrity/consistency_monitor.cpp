#include "navbus/core/integrity/consistency_monitor.hpp"

#include <algorithm>

#include "navbus/core/math/chi_square.hpp"

namespace navbus::core {

void ConsistencyMonitor::configure(const ConsistencyConfig& config) {
  config_ = config;
  config_.window_epochs = std::clamp(config_.window_epochs, 1, kMaxWindow);
  counters_ = {};
  restart();
}

void ConsistencyMonitor::restart() {
  count_ = 0;
  next_ = 0;
  inconsistent_ = false;
  reinitialise_due_ = false;
  last_probability_ = 1.0;
  window_nis_per_row_ = 0.0;
}

void ConsistencyMonitor::onEpoch(std::int64_t time_ns, double nis, int dof) {
  if (!config_.enabled || dof <= 0) return;
  counters_.nis_sum += nis;
  counters_.rows += static_cast<std::uint64_t>(dof);
  window_[static_cast<std::size_t>(next_)] = {nis, dof};
  next_ = (next_ + 1) % config_.window_epochs;
  count_ = std::min(count_ + 1, config_.window_epochs);
  if (count_ < config_.window_epochs) return;
  double sum = 0.0;
  int sum_dof = 0;
  for (int i = 0; i < count_; ++i) {
    sum += window_[static_cast<std::size_t>(i)].nis;
    sum_dof += window_[static_cast<std::size_t>(i)].dof;
  }
  last_probability_ = chiSquareSurvival(sum, sum_dof);
  window_nis_per_row_ = sum / static_cast<double>(sum_dof);
  ++counters_.epochs_tested;
  const bool failed = last_probability_ < config_.false_alarm_probability;
  if (failed) {
    ++counters_.epochs_inconsistent;
    if (!inconsistent_) {
      ++counters_.alarms;
      alarm_since_ns_ = time_ns;
    }
    const double lasted_s = 1e-9 * static_cast<double>(time_ns - alarm_since_ns_);
    if (!reinitialise_due_ && lasted_s >= config_.reinitialise_after_s) {
      reinitialise_due_ = true;
      ++counters_.reinitialisations;
    }
  }
  inconsistent_ = failed;
  if (!failed) reinitialise_due_ = false;
}

}  // namespace navbus::core
