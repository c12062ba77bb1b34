#include "navbus/nav_filter/combined_imu.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/conversions.hpp"

namespace navbus::nav_filter {

namespace {

using core::ImuInstrument;

constexpr ImuInstrument kKinds[] = {ImuInstrument::kGyro, ImuInstrument::kAccelerometer};

/// The units as the combination sees them: each one's noise of one sample from the filter's
/// white-noise densities (every lane takes the same).
std::vector<core::ImuArrayUnit> arrayUnits(const FilterConfig& config) {
  const double dt = 1e-9 * static_cast<double>(config.imu.period_ns);
  const core::FilterTuning& t = config.engine.tuning;
  std::vector<core::ImuArrayUnit> units;
  for (const LaneUnit& u : config.lanes.units)
    units.push_back({u.c_b_u.transpose(), u.lever_arm_b_m,
                     t.gyro_noise_radps_per_sqrthz * std::sqrt(dt),
                     t.accel_noise_mps2_per_sqrthz * std::sqrt(dt)});
  return units;
}

/// The combination's largest per-axis sigma over one unit's, with the worst single instrument
/// of that kind out (all of it when none can leave).
double noiseFactor(const core::ImuArrayCombination& all, ImuInstrument kind, double unit_sigma) {
  double worst = all.sigma(kind).maxCoeff();
  for (int u = 0; u < all.units(); ++u) {
    for (int a = 0; a < 3; ++a) {
      core::ImuArrayCombination one_out = all;
      if (one_out.exclude(kind, u, a)) worst = std::max(worst, one_out.sigma(kind).maxCoeff());
    }
  }
  return worst / unit_sigma;
}

}  // namespace

CombinedImu::CombinedImu(const FilterConfig& config)
    : units_(arrayUnits(config)),
      lane_id_(*config.lanes.least_squares_lane_id),
      period_ns_(config.imu.period_ns),
      lane_config_(config),
      aligner_(static_cast<int>(config.lanes.units.size()),
               static_cast<std::size_t>(config.lanes.least_squares_alignment_depth)) {
  makeCombination();
  FilterConfig& c = lane_config_;
  c.lanes = {};
  c.imu.id = lane_id_;
  c.imu_mounting.sensor_to_body = Eigen::Matrix3d::Identity();
  c.low_latency_output = false;
  // Its increments come once the parity test has judged their time (lane_set.hpp): the merge
  // waits for them as long as for that judgement, beyond its usual wait.
  if (c.fault_monitor)
    c.imu.max_wait_ns = c.sequencer_max_wait_ns + c.fault_monitor->judgement_wait_ns;
  core::FilterTuning& t = c.engine.tuning;
  const double gyro = noiseFactor(*combination_, ImuInstrument::kGyro, units_[0].gyro_sigma_rad);
  const double accel =
      noiseFactor(*combination_, ImuInstrument::kAccelerometer, units_[0].accel_sigma_mps);
  t.gyro_noise_radps_per_sqrthz *= gyro;
  t.gyro_bias_rw_radps_per_sqrts *= gyro;
  t.accel_noise_mps2_per_sqrthz *= accel;
  t.accel_bias_rw_mps2_per_sqrts *= accel;
  spdlog::info(
      "least-squares lane {}: {} units combined; its noise densities and bias walks are {:.3f} "
      "(gyros) and {:.3f} (accelerometers) of one unit's (eq. 1, the worst instrument out)",
      lane_id_, units_.size(), gyro, accel);
}

void CombinedImu::makeCombination() {
  std::string error;
  combination_ =
      core::ImuArrayCombination::make(units_, 1e-9 * static_cast<double>(period_ns_), error);
  if (!combination_) throw bus::ConfigError("configuration lanes.least_squares: " + error);
  initial_ = combination_;
  changes_.clear();
}

const core::ImuArrayCombination& CombinedImu::combinationAt(std::int64_t time_ns) const {
  const core::ImuArrayCombination* c = &*initial_;
  for (const auto& [from_ns, changed] : changes_)
    if (from_ns <= time_ns) c = &changed;
  return *c;
}

void CombinedImu::onIncrement(int unit, const navbus::ImuIncrement& msg) {
  if (bus::validate(msg, limits_)) {
    ++counters_.invalid;  // its time is combined without it
    return;
  }
  if (std::llabs(static_cast<long long>(msg.interval_ns()) - period_ns_) > 1) {
    ++counters_.wrong_interval;
    return;
  }
  const auto u = static_cast<std::size_t>(unit);
  const auto time_ns = static_cast<std::int64_t>(msg.time_gps_ns());
  // Sequence and time both back: a new run of the units' source (as the lanes' gates see it).
  if (msg.seq() < latest_seq_[u] && time_ns < aligner_.latestNs(unit)) startNewRun();
  latest_seq_[u] = msg.seq();
  if (aligner_.add(unit, bus::toCore(msg)) != bus::ImuUnitAligner::Added::kTaken) {
    ++counters_.late;
    return;
  }
  ++counters_.increments;
}

void CombinedImu::startNewRun() {
  makeCombination();  // as configured (it was made so once: it cannot fail now)
  aligner_.clear();
  exclusions_.clear();
  latest_seq_.fill(0);
  ended_left_ = 0;
  usable_ = true;
  seq_ = 0;  // the lane's own stream starts over at 1: its gate sees the restart
  ++counters_.new_runs;
}

void CombinedImu::exclude(ImuInstrument kind, int unit, int axis, std::int64_t from_ns) {
  exclusions_.push_back({kind, unit, axis, from_ns});
}

void CombinedImu::applyExclusions(std::int64_t time_ns, Output& out) {
  for (auto it = exclusions_.begin(); it != exclusions_.end();) {
    if (it->from_ns > time_ns) {
      ++it;
      continue;
    }
    const bool out_now = it->axis < 0 ? combination_->excludeUnit(it->unit)
                                      : combination_->exclude(it->kind, it->unit, it->axis);
    const bool already = it->axis >= 0 && !combination_->included(it->kind, it->unit, it->axis);
    if (out_now) {
      ++counters_.excluded;
      changes_.emplace_back(time_ns, *combination_);
      for (const ImuInstrument k : kKinds)
        if (it->axis < 0 || k == it->kind) out.relearn[static_cast<std::size_t>(k)] = true;
    } else if (!already && usable_) {
      usable_ = false;
      out.unusable = true;
      spdlog::warn(
          "least-squares lane {}: IMU unit {} {} cannot leave the combination at {:.3f} s (the "
          "rest would not span three axes): the lane is unusable from there",
          lane_id_, it->unit,
          it->axis < 0 ? std::string("(whole)") : fmt::format("axis {}", it->axis),
          1e-9 * static_cast<double>(time_ns));
    }
    it = exclusions_.erase(it);
  }
}

std::optional<CombinedImu::Output> CombinedImu::next(std::int64_t judged_ns, bool all) {
  while (true) {
    std::optional<bus::ImuUnitAligner::Sample> s =
        all ? aligner_.flushNext() : aligner_.next(judged_ns);
    if (!s) return std::nullopt;
    Output out;
    // A unit whose stream ended leaves whole at its first time missing.
    for (int u = 0; u < combination_->units(); ++u) {
      const std::uint32_t bit = 1u << static_cast<unsigned>(u);
      if ((s->present & bit) || !aligner_.ended(u) || (ended_left_ & bit)) continue;
      ended_left_ |= bit;
      exclusions_.push_back({ImuInstrument::kGyro, u, -1, s->time_ns});
    }
    applyExclusions(s->time_ns, out);
    if (!aligner_.complete(*s)) ++counters_.incomplete;
    const std::optional<core::ImuIncrement> inc = combination_->combine(s->units, s->present);
    if (!inc) {
      ++counters_.not_spanning;
      continue;
    }
    ++counters_.combined;
    out.increment = bus::toIdl(*inc, lane_id_, ++seq_);
    return out;
  }
}

std::string CombinedImu::summary() const {
  const Counters& c = counters_;
  std::ostringstream s;
  s << "least-squares lane " << lane_id_ << ": " << c.combined << " combined increments of "
    << units_.size() << " units (" << c.increments << " taken), instruments taken out "
    << c.excluded << (usable_ ? "" : ", unusable");
  if (c.invalid + c.wrong_interval + c.late + c.incomplete + c.not_spanning + c.new_runs > 0)
    s << "; not used: invalid " << c.invalid << ", other interval " << c.wrong_interval << ", late "
      << c.late << "; times without a unit " << c.incomplete << ", not spanning three axes "
      << c.not_spanning << "; new runs " << c.new_runs;
  return s.str();
}

}  // namespace navbus::nav_filter
