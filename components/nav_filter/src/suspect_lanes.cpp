#include "navbus/nav_filter/suspect_lanes.hpp"

#include <cmath>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "navbus/core/math/units.hpp"

namespace navbus::nav_filter {

namespace {
const char* instrumentName(bool accelerometer) {
  return accelerometer ? "accelerometer" : "gyro";
}
}  // namespace

SuspectLanes::SuspectLanes(const std::vector<LaneUnit>& units,
                           const core::LaneEvidenceConfig& config)
    : units_(units), test_(config), history_(units.size(), History(kHistory)) {}

std::string SuspectLanes::onSuspect(const Suspect& s) {
  if (!first_ || first_->decision_id != s.decision_id || first_->lane == s.lane) {
    first_ = s;
    return fmt::format("IMU {} {} axis {}: suspect of decision {}, waiting for the other candidate",
                       units_[static_cast<std::size_t>(s.lane)].sensor_id,
                       instrumentName(s.accelerometer), "xyz"[s.axis], s.decision_id);
  }
  if (question_) ++counters_.superseded;
  question_ = Question{{*first_, s}, std::nullopt};
  first_.reset();
  ++counters_.questions;
  question_->reference = referenceFromHistory(*question_);
  return fmt::format("IMU {} or IMU {}: the lanes compare their estimates since the onset",
                     units_[static_cast<std::size_t>(question_->suspects[0].lane)].sensor_id,
                     units_[static_cast<std::size_t>(s.lane)].sensor_id);
}

std::optional<SuspectLanes::Named> SuspectLanes::atSelection(
    std::int64_t time_ns, const std::vector<const navbus::NavigationSolution*>& at) {
  for (std::size_t k = 0; k < at.size(); ++k) {
    if (!at[k]) continue;
    if (history_[k].size() == kHistory) history_[k].pop_front();  // full: the oldest goes
    history_[k].push_back(inUnitAxes(k, *at[k]));
  }
  if (!question_) return std::nullopt;
  Question& q = *question_;
  const auto a = static_cast<std::size_t>(q.suspects[0].lane);
  const auto b = static_cast<std::size_t>(q.suspects[1].lane);
  if (!at[a] || !at[b]) {
    if (time_ns > q.suspects[0].onset_ns) ++counters_.unpaired;
    return std::nullopt;
  }
  const std::array<core::LaneBiasEstimate, 2> now{instrument(history_[a].back(), q.suspects[0]),
                                                  instrument(history_[b].back(), q.suspects[1])};
  if (time_ns < q.suspects[0].onset_ns) {
    q.reference = now;  // the last time before the fault
    return std::nullopt;
  }
  if (!q.testing) {
    if (!q.reference) q.reference = now;  // no time before the onset in this run
    test_.open(q.suspects[0].onset_ns, *q.reference);
    q.testing = true;
  }
  const auto decision = test_.update(time_ns, now);
  if (!decision) {
    if (!test_.isOpen()) {
      ++counters_.expired;
      spdlog::warn(
          "lanes: IMU {} or IMU {}: neither lane's estimate moved within the wait; the "
          "ambiguity stays",
          units_[a].sensor_id, units_[b].sensor_id);
      question_.reset();
    }
    return std::nullopt;
  }
  Named n{q.suspects[static_cast<std::size_t>(decision->candidate)], time_ns, *decision};
  question_.reset();
  ++counters_.named;
  named_.push_back(n);
  const bool accel = n.suspect.accelerometer;
  const double to_unit = 1.0 / (accel ? units::kMicroG : units::kDegPerHour);
  spdlog::warn(
      "lanes: IMU {} {} axis {} named at {:.3f} s (decision {}): {}; its estimate moved {:.4g} {} "
      "(+- {:.2g}), |Lambda| {:.4g} (h {:.4g}); its lane is left",
      units_[static_cast<std::size_t>(n.suspect.lane)].sensor_id, instrumentName(accel),
      "xyz"[n.suspect.axis], 1e-9 * static_cast<double>(time_ns), n.suspect.decision_id,
      decision->kind == core::LaneEvidenceKind::kBiasMoved
          ? "its lane's bias estimate moved, the other's did not"
          : "its lane failed its own consistency test, the other's holds",
      decision->bias_change * to_unit, accel ? "ug" : "deg/h", decision->change_sigma * to_unit,
      decision->statistic, decision->threshold);
  return n;
}

void SuspectLanes::newRun() {
  for (auto& h : history_) h.clear();
  first_.reset();
  question_.reset();
}

SuspectLanes::Estimates SuspectLanes::inUnitAxes(std::size_t lane,
                                                 const navbus::NavigationSolution& s) const {
  // The lane estimates its unit's biases in body axes (its increments turned by the mounting):
  // b_u = C_u_b b_b, each axis's variance from the body axes' (their correlations not
  // published).
  const Eigen::Matrix3d c_u_b = units_[lane].c_b_u.transpose();
  Estimates e;
  e.time_ns = static_cast<std::int64_t>(s.time_gps_ns());
  // Its own consistency test (and the re-initialisation a lasting failure leads to).
  const bool consistent = (s.active_fault_flags() & navbus::FAULT_FILTER_INCONSISTENT) == 0 &&
                          s.mode() != navbus::MODE_REINITIALISING;
  for (int kind = 0; kind < 2; ++kind) {
    const auto& bias = kind == 0 ? s.gyro_bias_b_radps() : s.accel_bias_b_mps2();
    const auto& sigma = kind == 0 ? s.gyro_bias_sigma_b_radps() : s.accel_bias_sigma_b_mps2();
    const Eigen::Vector3d b(bias[0], bias[1], bias[2]);
    const Eigen::Vector3d var(sigma[0] * sigma[0], sigma[1] * sigma[1], sigma[2] * sigma[2]);
    const Eigen::Vector3d b_u = c_u_b * b;
    const Eigen::Vector3d var_u = c_u_b.cwiseAbs2() * var;
    for (int axis = 0; axis < 3; ++axis)
      e.instruments[static_cast<std::size_t>(kind * 3 + axis)] = {b_u[axis], std::sqrt(var_u[axis]),
                                                                  consistent};
  }
  return e;
}

core::LaneBiasEstimate SuspectLanes::instrument(const Estimates& e, const Suspect& s) {
  return e.instruments[static_cast<std::size_t>((s.accelerometer ? 3 : 0) + s.axis)];
}

std::optional<std::array<core::LaneBiasEstimate, 2>> SuspectLanes::referenceFromHistory(
    const Question& q) {
  const auto& ha = history_[static_cast<std::size_t>(q.suspects[0].lane)];
  const auto& hb = history_[static_cast<std::size_t>(q.suspects[1].lane)];
  if (ha.empty() || hb.empty()) return std::nullopt;  // the selection has not begun
  const std::int64_t onset = q.suspects[0].onset_ns;
  if (ha.back().time_ns < onset) return std::nullopt;  // the selection will pass the onset
  // The latest time both lanes kept before the onset.
  for (std::size_t ia = ha.size(); ia-- > 0;) {
    if (ha[ia].time_ns >= onset) continue;
    for (std::size_t ib = hb.size(); ib-- > 0;) {
      if (hb[ib].time_ns == ha[ia].time_ns)
        return std::array<core::LaneBiasEstimate, 2>{instrument(ha[ia], q.suspects[0]),
                                                     instrument(hb[ib], q.suspects[1])};
      if (hb[ib].time_ns < ha[ia].time_ns) break;
    }
  }
  ++counters_.old_onset;  // before everything kept: the oldest common time stands for it
  return std::array<core::LaneBiasEstimate, 2>{instrument(ha.front(), q.suspects[0]),
                                               instrument(hb.front(), q.suspects[1])};
}

std::string SuspectLanes::summary() const {
  const Counters& c = counters_;
  std::ostringstream s;
  s << "suspect units compared " << c.questions << ", named " << c.named << ", undecided within "
    << "the wait " << c.expired << ", superseded " << c.superseded;
  if (c.unpaired + c.old_onset > 0)
    s << ", times without both lanes " << c.unpaired << ", onsets before the history "
      << c.old_onset;
  for (const Named& n : named_)
    s << "; IMU " << units_[static_cast<std::size_t>(n.suspect.lane)].sensor_id << " "
      << instrumentName(n.suspect.accelerometer) << " axis "
      << "xyz"[n.suspect.axis] << " at "
      << fmt::format("{:.3f}", 1e-9 * static_cast<double>(n.time_ns)) << " s";
  return s.str();
}

}  // namespace navbus::nav_filter
