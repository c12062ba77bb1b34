// The engine's honesty when its model stops fitting: the consistency monitor's verdict on
// each aiding epoch, and the re-initialisation from an independent GNSS solution that a
// lasting alarm or an inertial gap beyond the bridge asks for (navigation_engine.hpp,
// EngineMode::kReinitialising).
#include <cmath>

#include "navbus/core/engine/initial_alignment.hpp"
#include "navbus/core/engine/navigation_engine.hpp"
#include "navbus/core/filter/integrated_filter.hpp"
#include "navbus/core/integrity/glr_protection_level.hpp"
#include "navbus/core/math/earth.hpp"

namespace navbus::core {

void NavigationEngine::checkConsistency(std::int64_t time_ns, const ScalarUpdateResult* rows,
                                        int n) {
  InnovationStatistics epoch;  // a row with no variance was not offered
  for (int i = 0; i < n; ++i) epoch.add(rows[i].innovation, rows[i].innovation_var);
  judgeConsistency(time_ns, epoch.nis_sum, static_cast<int>(epoch.rows));
}

void NavigationEngine::checkConsistency(std::int64_t time_ns,
                                        const std::vector<MeasurementReport>& reports) {
  InnovationStatistics epoch;
  for (const MeasurementReport& r : reports) {
    if (r.fused) epoch.add(r.result.innovation, r.result.innovation_var);
  }
  judgeConsistency(time_ns, epoch.nis_sum, static_cast<int>(epoch.rows));
}

void NavigationEngine::judgeConsistency(std::int64_t time_ns, double nis, int dof) {
  const std::uint64_t alarms_before = consistency_.counters().alarms;
  consistency_.onEpoch(time_ns, nis, dof);
  if (consistency_.counters().alarms != alarms_before &&
      config_.consistency.inflate_imu_biases_on_alarm) {
    // The model stopped fitting: let the biases be learnt again (a shifted sensor bias is
    // what the filter can recover from; its solution stays flagged while the window fails).
    filter_->inflateVariances(layout::kAccelBias, config_.tuning.accel_bias_sigma_mps2);
    filter_->inflateVariances(layout::kGyroBias, config_.tuning.gyro_bias_sigma_radps);
    ++counters_.bias_inflations;
  }
  if (consistency_.inconsistent()) {
    status_ |= kStatusInconsistent;
  } else {
    status_ &= ~static_cast<std::uint32_t>(kStatusInconsistent);
  }
  if (consistency_.reinitialisationDue()) askReinitialisation();
}

void NavigationEngine::askReinitialisation() {
  if ((status_ & kStatusReinitialising) != 0) return;
  status_ |= kStatusReinitialising;
  ++counters_.reinitialisations_asked;
}

bool NavigationEngine::reinitialiseFromPseudoranges(std::int64_t time_ns) {
  const PseudorangeFix pf = pseudorangeFix(time_ns, firstReceiverObservations(),
                                           earth::geodeticToEcef(filter_->state().position));
  if (!pf.valid) return false;
  filter_->resetNavigation(pf.fix);
  filter_->resetClock(pf.clock_bias_m, pf.clock_drift_mps, pf.clock_bias_sigma_m,
                      pf.clock_drift_sigma_mps);
  finishReinitialisation();
  return true;
}

void NavigationEngine::reinitialiseFromFix(const GnssFixMeasurement& fix) {
  filter_->resetNavigation(fix);
  finishReinitialisation();
}

void NavigationEngine::finishReinitialisation() {
  status_ &= ~static_cast<std::uint32_t>(kStatusReinitialising | kStatusInconsistent);
  consistency_.restart();
  integrity_->reset();  // the hypotheses describe the filter before the new start
  ++counters_.reinitialisations_done;
}

}  // namespace navbus::core
