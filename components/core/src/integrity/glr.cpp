#include "navbus/core/integrity/glr.hpp"

#include <algorithm>

#include "navbus/core/integrity/glr_group_fit.hpp"
#include "navbus/core/integrity/glr_isolation.hpp"

namespace navbus::core {

using namespace glr;

const char* glrFaultName(GlrFault fault) {
  switch (fault) {
    case GlrFault::kAccelStep:
      return "accelerometer step";
    case GlrFault::kGyroStep:
      return "gyro step";
    case GlrFault::kRangeStep:
      return "pseudorange step";
    case GlrFault::kRangeRamp:
      return "pseudorange ramp";
    case GlrFault::kRateStep:
      return "pseudorange-rate step";
  }
  return "unknown";
}

GlrMonitor::GlrMonitor() : GlrMonitor(GlrConfig{}) {}

GlrMonitor::GlrMonitor(const GlrConfig& config) {
  configure(config);
}

void GlrMonitor::configure(const GlrConfig& config) {
  config_ = config;
  config_.window = std::clamp(config.window, 1, kMaxWindow);
  window_.configure(config_);
  result_ = GlrResult{};
}

void GlrMonitor::reset() {
  window_.reset();
  result_ = GlrResult{};
}

const GlrResult& GlrMonitor::update(const GlrEpoch& e) {
  if (!window_.accepts(e) || !window_.update(e)) {
    ++refused_;
    result_ = GlrResult{};
    return result_;
  }
  ++epochs_;
  evaluate();
  return result_;
}

void GlrMonitor::evaluate() {
  result_ = GlrResult{};
  result_.valid = true;
  result_.threshold = config_.threshold;
  int best_age = -1;
  double best = 0.0;
  for (int age = 0; age < window_.onsetCount(); ++age) {
    const double l = onsetStatistic(window_.onset(age));
    if (best_age < 0 || l > best) {
      best = l;
      best_age = age;
    }
  }
  if (best_age < 0) return;
  result_.statistic = best;
  result_.detected = best >= config_.threshold;
  if (result_.detected) {
    isolateOnset(window_, config_, best_age, result_);  // eqs. 14-16 at detection time
  } else {
    result_.onset_epochs_ago = best_age;
    result_.onset_time_ns = window_.onset(best_age).ramp_start_ns;
  }
}

double GlrMonitor::onsetStatistic(const GlrWindow::OnsetView& o) const {
  double l = 0.0;
  if (config_.imu_steps) {
    l = glr::fitGroup<kImuDirections>(o.r_imu, o.f.head<kImuDirections>(), config_.rank_tolerance)
            .statistic;
  }
  for (int s = 0; s < window_.slotsUsed(); ++s) {
    if (window_.slot(s).quarantined) continue;
    const Eigen::Vector3d f = o.f.segment<kSatDirections>(satColumn(s, 0));
    l = std::max(l, satelliteGroupStatistic(o.rSat(s), f, config_.rank_tolerance));
  }
  return l;
}

GlrResult GlrMonitor::isolationAt(int onset_age) const {
  GlrResult r;
  if (onset_age < 0 || onset_age >= window_.onsetCount()) return r;
  r.valid = true;
  r.threshold = config_.threshold;
  isolateOnset(window_, config_, onset_age, r);
  r.statistic = onsetStatistic(window_.onset(onset_age));
  r.detected = r.statistic >= config_.threshold;
  return r;
}

int GlrMonitor::onsetAge(std::int64_t onset_time_ns) const {
  for (int age = 0; age < window_.onsetCount(); ++age) {
    if (window_.onset(age).ramp_start_ns == onset_time_ns) return age;
  }
  return -1;
}

GlrMonitor::DirectionSums GlrMonitor::directionSums(int age, const GlrHypothesis& h) const {
  if (age < 0 || age >= window_.onsetCount()) return {};
  const GlrWindow::OnsetView o = window_.onset(age);
  if (h.isImu()) {
    const int j = (h.fault == GlrFault::kAccelStep ? 0 : 3) + std::clamp(h.axis, 0, 2);
    return {o.f[j], o.r_imu(j, j)};
  }
  const int slot = window_.slotOf(h.sv_id, h.receiver);
  if (slot < 0) return {};
  const int j = h.fault == GlrFault::kRangeStep   ? kRangeStep
                : h.fault == GlrFault::kRangeRamp ? kRangeRamp
                                                  : kRateStep;
  return {o.f[satColumn(slot, j)], o.rSat(slot)(j, j)};
}

double GlrMonitor::imuStatistic(int age) const {
  if (age < 0 || age >= window_.onsetCount()) return 0.0;
  const GlrWindow::OnsetView o = window_.onset(age);
  return glr::fitGroup<kImuDirections>(o.r_imu, o.f.head<kImuDirections>(), config_.rank_tolerance)
      .statistic;
}

double GlrMonitor::satelliteStatistic(int age, int sv_id) const {
  if (age < 0 || age >= window_.onsetCount()) return 0.0;
  const int slot = window_.slotOf(sv_id);
  if (slot < 0) return 0.0;
  const GlrWindow::OnsetView o = window_.onset(age);
  const Eigen::Vector3d f = o.f.segment<kSatDirections>(satColumn(slot, 0));
  return glr::fitGroup<kSatDirections>(o.rSat(slot), f, config_.rank_tolerance).statistic;
}

}  // namespace navbus::core
