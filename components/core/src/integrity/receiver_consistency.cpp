#include "navbus/core/integrity/receiver_consistency.hpp"

#include <algorithm>
#include <cmath>

#include "navbus/core/math/chi_square.hpp"

namespace navbus::core {

namespace {
double meanOf(const std::vector<ReceiverSatellite>& sats, double ReceiverSatellite::*field) {
  double sum = 0.0;
  for (const ReceiverSatellite& s : sats) sum += s.*field;
  return sats.empty() ? 0.0 : sum / static_cast<double>(sats.size());
}

const ReceiverSatellite* find(const std::vector<ReceiverSatellite>& sats, int sv_id) {
  for (const ReceiverSatellite& s : sats)
    if (s.sv_id == sv_id) return &s;
  return nullptr;
}
}  // namespace

ReceiverClockMonitor::ReceiverClockMonitor(const ReceiverClockConfig& config)
    : config_(config), threshold_(chiSquareQuantile(config.false_alarm_probability, 1)) {}

std::optional<ClockJump> ReceiverClockMonitor::update(
    double time_s, const std::vector<ReceiverSatellite>& satellites) {
  ranges_.clear();
  for (const ReceiverSatellite& s : satellites) ranges_.push_back(s.range);
  const LeastSquaresFix fix = leastSquaresFix(ranges_, position_ecef_m_);
  if (!fix.valid) {
    have_previous_ = false;
    return std::nullopt;
  }
  const double bias_sigma = fix.tdop * meanOf(satellites, &ReceiverSatellite::pseudorange_sigma_m);
  const double drift_sigma = fix.tdop * meanOf(satellites, &ReceiverSatellite::rate_sigma_mps);
  std::optional<ClockJump> jump;
  if (have_previous_) {
    const double dt = time_s - time_s_;
    const double v = fix.clock_bias_m - (bias_m_ + drift_mps_ * dt);
    const double qb = config_.bias_noise_m_per_sqrts * config_.bias_noise_m_per_sqrts;
    const double qd = config_.drift_noise_mps_per_sqrts * config_.drift_noise_mps_per_sqrts;
    const double var = bias_sigma * bias_sigma + bias_sigma_m_ * bias_sigma_m_ +
                       drift_sigma_mps_ * drift_sigma_mps_ * dt * dt + qb * dt +
                       qd * dt * dt * dt / 3.0;  // eq. 2
    const double statistic = v * v / var;
    largest_ = std::max(largest_, statistic);
    if (statistic >= threshold_) jump = ClockJump{v, statistic, threshold_};
  }
  // The new clock is followed from here (after a jump too: its size is reported once).
  have_previous_ = true;
  time_s_ = time_s;
  bias_m_ = fix.clock_bias_m;
  drift_mps_ = fix.clock_drift_mps;
  bias_sigma_m_ = bias_sigma;
  drift_sigma_mps_ = drift_sigma;
  position_ecef_m_ = fix.pos_ecef_m;
  return jump;
}

ReceiverPairConsistency::ReceiverPairConsistency(const ParityGlrConfig& config, double baseline_m)
    : config_(config), baseline_variance_m2_(baseline_m * baseline_m / 3.0) {}

void ReceiverPairConsistency::exclude(int sv_id) {
  excluded_.push_back(sv_id);
  glr_.reset();
}

const PairConsistencyResult& ReceiverPairConsistency::update(
    const std::vector<ReceiverSatellite>& reference, const std::vector<ReceiverSatellite>& other) {
  std::vector<int> shared;
  differences_.resize(0);
  sigmas_.resize(0);
  for (const ReceiverSatellite& a : reference) {
    const ReceiverSatellite* b = find(other, a.sv_id);
    if (!b || std::find(excluded_.begin(), excluded_.end(), a.sv_id) != excluded_.end()) continue;
    if (static_cast<int>(shared.size()) == parity::kMaxInstruments) break;
    shared.push_back(a.sv_id);
  }
  const auto n = static_cast<Eigen::Index>(shared.size());
  differences_.resize(n);
  sigmas_.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const ReceiverSatellite* a = find(reference, shared[static_cast<std::size_t>(i)]);
    const ReceiverSatellite* b = find(other, shared[static_cast<std::size_t>(i)]);
    differences_[i] = a->range.pseudorange_m - b->range.pseudorange_m;  // eq. 1
    sigmas_[i] = std::sqrt(a->pseudorange_sigma_m * a->pseudorange_sigma_m +
                           b->pseudorange_sigma_m * b->pseudorange_sigma_m + baseline_variance_m2_);
  }
  // A new shared set is a new space: its onsets start again.
  if (shared != result_.sv_ids || !glr_) {
    glr_.reset();
    result_ = PairConsistencyResult{};
    result_.sv_ids = shared;
    if (n >= 2) {
      std::optional<ParitySpace> space = ParitySpace::makeCommonMode(sigmas_, error_);
      if (space) glr_ = ParityGlr::make(*space, config_, error_);
    }
  }
  result_.glr = ParityGlrResult{};
  result_.sv_id = result_.runner_up_sv = 0;
  if (!glr_) return result_;
  result_.glr = glr_->update(differences_);
  if (result_.glr.instrument >= 0)
    result_.sv_id = shared[static_cast<std::size_t>(result_.glr.instrument)];
  if (result_.glr.runner_up >= 0)
    result_.runner_up_sv = shared[static_cast<std::size_t>(result_.glr.runner_up)];
  return result_;
}

double ReceiverPairConsistency::minimumDetectableDifference() const {
  if (!glr_) return 0.0;
  double largest = 0.0;
  for (int j = 0; j < glr_->space().instruments(); ++j)
    largest = std::max(largest, glr_->minimumDetectableBias(j));
  return largest;
}

}  // namespace navbus::core
