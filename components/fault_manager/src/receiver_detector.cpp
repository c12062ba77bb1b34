#include "navbus/fault_manager/receiver_detector.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <spdlog/spdlog.h>

#include "navbus/core/math/earth.hpp"

namespace navbus::fault_manager {

namespace {

Eigen::Vector3d vec(const std::array<double, 3>& a) {
  return {a[0], a[1], a[2]};
}

navbus::FaultCandidate candidate(navbus::FaultSource source, std::uint32_t receiver, int sv_id,
                                 double statistic, double magnitude) {
  navbus::FaultCandidate c;
  c.source(source);
  c.sensor_id(receiver);
  c.sv_id(static_cast<std::uint16_t>(sv_id));
  c.shape(navbus::SHAPE_STEP);
  c.statistic(statistic);
  c.magnitude(magnitude);
  return c;
}

}  // namespace

ReceiverDetector::ReceiverDetector(const ReceiverDetectorConfig& config) : config_(config) {
  const std::size_t n = config_.receiver_ids.size();
  for (std::size_t r = 0; r < n; ++r) clocks_.emplace_back(config_.clock);
  for (std::size_t r = 1; r < n; ++r) {
    const double baseline = (config_.antennas_b_m[r] - config_.antennas_b_m[0]).norm();
    pairs_.emplace_back(config_.glr, baseline);
  }
  pair_times_.resize(pairs_.size());
  gone_after_ns_.assign(n, std::numeric_limits<std::int64_t>::max());
  latest_ns_.assign(n, 0);
  spdlog::info(
      "receiver detector: {} receivers (reference {}), clock jumps beyond the chi-square "
      "threshold {:.4g} (P_fa {:.1e} per epoch), shared satellites' differences by a parity GLR "
      "({} onsets, P_fa {:.1e} per epoch)",
      n, config_.receiver_ids[0], clocks_[0].threshold(), config_.clock.false_alarm_probability,
      config_.glr.onsets, config_.glr.false_alarm_probability);
}

int ReceiverDetector::receiverOf(std::uint32_t id) const {
  for (std::size_t r = 0; r < config_.receiver_ids.size(); ++r)
    if (config_.receiver_ids[r] == id) return static_cast<int>(r);
  return -1;
}

ReceiverDetector::Epoch ReceiverDetector::toCore(const navbus::GnssObservationEpoch& msg) {
  Epoch out;
  for (const navbus::GnssSatelliteMeasurement& m : msg.satellites()) {
    core::ReceiverSatellite s;
    s.sv_id = m.sv_id();
    s.range.sat_pos_ecef_m = vec(m.sat_pos_ecef_m());
    s.range.sat_vel_ecef_mps = vec(m.sat_vel_ecef_mps());
    // The satellite's clock applied (GnssSatelliteMeasurement's convention).
    s.range.pseudorange_m = m.pseudorange_m() + m.sat_clock_correction_m();
    s.range.pseudorange_rate_mps = m.pseudorange_rate_mps() + m.sat_clock_drift_mps();
    s.pseudorange_sigma_m = m.pseudorange_sigma_m();
    s.rate_sigma_mps = m.pseudorange_rate_sigma_mps();
    const bool finite =
        s.range.sat_pos_ecef_m.allFinite() && s.range.sat_vel_ecef_mps.allFinite() &&
        std::isfinite(s.range.pseudorange_m) && std::isfinite(s.range.pseudorange_rate_mps);
    if (!m.valid() || !finite || !(s.pseudorange_sigma_m > 0.0) || !(s.rate_sigma_mps > 0.0)) {
      ++counters_.satellites_left_out;
      continue;
    }
    out.push_back(s);
  }
  return out;
}

void ReceiverDetector::onEpoch(const navbus::GnssObservationEpoch& msg, FaultOutput& out) {
  const int r = receiverOf(msg.receiver_id());
  if (r < 0) {
    ++counters_.other_receivers;
    return;
  }
  ++counters_.epochs;
  const auto time_ns = static_cast<std::int64_t>(msg.time_gps_ns());
  const auto rx = static_cast<std::size_t>(r);
  latest_ns_[rx] = std::max(latest_ns_[rx], time_ns);
  if (time_ns > gone_after_ns_[rx])  // delivers again after its end: waited for again
    gone_after_ns_[rx] = std::numeric_limits<std::int64_t>::max();
  if (time_ns <= last_tested_ns_) {
    ++counters_.late;
    return;
  }
  Slot& slot = pending_[time_ns];
  slot.receivers.resize(config_.receiver_ids.size());
  auto& own = slot.receivers[static_cast<std::size_t>(r)];
  if (own) {
    ++counters_.late;  // repeated
    return;
  }
  own = toCore(msg);
  ++slot.received;
  drain(out);
}

void ReceiverDetector::receiverGone(std::uint32_t id, std::int64_t last_time_ns, FaultOutput& out) {
  const int r = receiverOf(id);
  if (r < 0) return;
  const auto rx = static_cast<std::size_t>(r);
  const std::int64_t gone_after_ns = std::max(last_time_ns, latest_ns_[rx]);
  if (gone_after_ns == gone_after_ns_[rx]) return;  // told again (by another reader)
  gone_after_ns_[rx] = gone_after_ns;
  spdlog::info(
      "receiver detector: receiver {} ended or lost after {:.3f} s: later times are "
      "tested without it",
      id, 1e-9 * static_cast<double>(gone_after_ns_[rx]));
  drain(out);
}

bool ReceiverDetector::complete(std::int64_t time_ns, const Slot& slot) const {
  for (std::size_t r = 0; r < slot.receivers.size(); ++r)
    if (!slot.receivers[r] && time_ns <= gone_after_ns_[r]) return false;
  return true;
}

void ReceiverDetector::drain(FaultOutput& out) {
  // Every time up to the latest complete one is settled: the complete ones are tested, the
  // incomplete ones before will not complete (each receiver delivers in time order). Beyond
  // that, the oldest times are dropped while too many wait.
  auto last_complete = pending_.end();
  for (auto it = pending_.begin(); it != pending_.end(); ++it)
    if (complete(it->first, it->second)) last_complete = it;
  const auto settle = [&](std::map<std::int64_t, Slot>::iterator it) {
    if (complete(it->first, it->second) && it->second.received >= 2) {
      if (it->second.received < config_.receiver_ids.size()) ++counters_.without_gone;
      test(it->first, it->second, out);
    } else {
      ++counters_.incomplete;
    }
    last_tested_ns_ = it->first;
    return pending_.erase(it);
  };
  if (last_complete != pending_.end()) {
    const auto stop = std::next(last_complete);
    for (auto it = pending_.begin(); it != stop;) it = settle(it);
  }
  while (pending_.size() > static_cast<std::size_t>(config_.alignment_depth))
    settle(pending_.begin());
}

void ReceiverDetector::test(std::int64_t time_ns, const Slot& slot, FaultOutput& out) {
  ++counters_.tested;
  // The satellites first: one that differs between receivers (decided now or before) is left out
  // of every receiver's clock test, whose least-squares clock would otherwise take it for a jump
  // (with four satellites a fix has no redundancy to tell a bad range from a clock step).
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    if (!slot.receivers[0] || !slot.receivers[k + 1]) continue;  // one of them gone
    const core::PairConsistencyResult& p =
        pairs_[k].update(*slot.receivers[0], *slot.receivers[k + 1]);
    std::deque<std::int64_t>& times = pair_times_[k];
    times.push_back(time_ns);
    while (times.size() > static_cast<std::size_t>(config_.glr.onsets * config_.glr.onset_spacing))
      times.pop_front();
    counters_.max_satellite_statistic =
        std::max(counters_.max_satellite_statistic, p.glr.statistic);
    if (!printed_detectable_ && pairs_[k].minimumDetectableDifference() > 0.0) {
      printed_detectable_ = true;
      spdlog::info(
          "receiver detector: receivers {} and {} share {} satellites; minimum detectable "
          "difference {:.3g} m (probability {} over {} epochs)",
          config_.receiver_ids[0], config_.receiver_ids[k + 1], p.sv_ids.size(),
          pairs_[k].minimumDetectableDifference(), config_.glr.detection_probability,
          config_.glr.onsets * config_.glr.onset_spacing);
    }
    if (p.glr.detected) reportSatellite(time_ns, k + 1, p, out);
  }
  const double time_s = 1e-9 * static_cast<double>(time_ns);
  for (std::size_t r = 0; r < clocks_.size(); ++r) {
    if (!slot.receivers[r]) continue;  // gone
    Epoch& consistent = scratch_;
    consistent.clear();
    for (const core::ReceiverSatellite& s : *slot.receivers[r])
      if (std::find(decided_svs_.begin(), decided_svs_.end(), s.sv_id) == decided_svs_.end())
        consistent.push_back(s);
    const std::optional<core::ClockJump> jump = clocks_[r].update(time_s, consistent);
    counters_.max_clock_statistic =
        std::max(counters_.max_clock_statistic, clocks_[r].largestStatistic());
    if (jump) reportClock(time_ns, r, *jump, out);
  }
}

void ReceiverDetector::reportClock(std::int64_t time_ns, std::size_t r, const core::ClockJump& j,
                                   FaultOutput& out) {
  navbus::FaultDecision d;
  d.time_gps_ns(static_cast<std::uint64_t>(time_ns));
  d.event(navbus::EVENT_FAULT_DETECTED);
  d.source(navbus::SOURCE_RECEIVER_CLOCK);
  d.sensor_id(config_.receiver_ids[r]);
  d.shape(navbus::SHAPE_STEP);
  d.test_statistic(j.statistic);
  d.threshold(j.threshold);
  d.magnitude(j.magnitude_m);
  d.onset_time_gps_ns(static_cast<std::uint64_t>(time_ns));  // since the epoch before
  d.detector(kDetectorName);
  d.candidates().push_back(candidate(navbus::SOURCE_RECEIVER_CLOCK, config_.receiver_ids[r], 0,
                                     j.statistic, j.magnitude_m));
  const std::uint32_t id = out.decide(d);
  ++counters_.clock_jumps;
  // The receiver's clock from the instant before this epoch on: the filter fuses the epoch
  // with its clock moved by the jump (sigma: the jump's, from v^2 / var v).
  navbus::FilterCommand c;
  c.kind(navbus::CMD_COMPENSATE_BIAS);
  c.decision_id(id);
  c.time_gps_ns(static_cast<std::uint64_t>(time_ns - 1));
  c.sensor(navbus::SOURCE_RECEIVER_CLOCK);
  c.sensor_id(config_.receiver_ids[r]);
  c.bias(j.magnitude_m);
  c.bias_sigma(std::abs(j.magnitude_m) / std::sqrt(j.statistic));
  out.command(c);
  spdlog::warn(
      "decision {}: receiver {} clock jumped {:.6g} m ({:.4g} ms), v^2/var {:.4g} >= {:.4g}", id,
      config_.receiver_ids[r], j.magnitude_m, 1e3 * j.magnitude_m / core::earth::kSpeedOfLight_mps,
      j.statistic, j.threshold);
}

void ReceiverDetector::reportSatellite(std::int64_t time_ns, std::size_t r,
                                       const core::PairConsistencyResult& p, FaultOutput& out) {
  const std::deque<std::int64_t>& times = pair_times_[r - 1];
  const std::size_t since =
      std::min<std::size_t>(static_cast<std::size_t>(p.glr.samples_since_onset), times.size());
  navbus::FaultDecision d;
  d.time_gps_ns(static_cast<std::uint64_t>(time_ns));
  d.event(navbus::EVENT_FAULT_DETECTED);
  d.source(navbus::SOURCE_SATELLITE);
  d.sensor_id(config_.receiver_ids[r]);
  d.sv_id(static_cast<std::uint16_t>(p.sv_id));
  d.shape(navbus::SHAPE_STEP);
  d.test_statistic(p.glr.statistic);
  d.threshold(p.glr.threshold);
  d.magnitude(p.glr.magnitude);
  d.onset_time_gps_ns(
      static_cast<std::uint64_t>(since > 0 ? times[times.size() - since] : time_ns));
  // Two receivers cannot say which of them measured the satellite wrong.
  d.ambiguous(true);
  d.detector(kDetectorName);
  for (const std::size_t receiver : {std::size_t{0}, r})
    d.candidates().push_back(candidate(navbus::SOURCE_SATELLITE, config_.receiver_ids[receiver],
                                       p.sv_id, p.glr.statistic, p.glr.magnitude));
  if (p.glr.ambiguous && p.runner_up_sv > 0)
    d.candidates().push_back(candidate(navbus::SOURCE_SATELLITE, config_.receiver_ids[r],
                                       p.runner_up_sv, p.glr.statistic, p.glr.magnitude));
  const std::uint32_t id = out.decide(d);
  ++counters_.satellites;
  // Out of the filter from before its onset (the filter's recovery margin) and before this
  // epoch is fused: which of the two receivers saw it wrong is unknown, so out of both.
  navbus::FilterCommand c;
  c.kind(navbus::CMD_EXCLUDE_SATELLITE);
  c.decision_id(id);
  c.time_gps_ns(static_cast<std::uint64_t>(time_ns - 1));
  c.onset_time_gps_ns(d.onset_time_gps_ns());
  c.sv_id(static_cast<std::uint16_t>(p.sv_id));
  c.scope(navbus::SCOPE_ALL);
  out.command(c);
  out.satelliteKeptOut(p.sv_id);
  spdlog::warn(
      "decision {}: sv {} differs between receivers {} and {} by {:.4g} m (+- {:.2g}){}, l {:.4g} "
      ">= h {:.4g}",
      id, p.sv_id, config_.receiver_ids[0], config_.receiver_ids[r], p.glr.magnitude,
      p.glr.magnitude_sigma,
      p.glr.ambiguous && p.runner_up_sv > 0 ? " or sv " + std::to_string(p.runner_up_sv) : "",
      p.glr.statistic, p.glr.threshold);
  pairs_[r - 1].exclude(p.sv_id);
  decided_svs_.push_back(p.sv_id);
}

std::string ReceiverDetector::summary() const {
  const Counters& c = counters_;
  std::ostringstream s;
  s << "receivers: " << c.tested << " aligned epochs of " << config_.receiver_ids.size()
    << " receivers (" << c.epochs << " epochs, other receivers " << c.other_receivers << ", late "
    << c.late << ", times incomplete " << c.incomplete << ", tested without a receiver gone "
    << c.without_gone << ", satellites left out " << c.satellites_left_out << "), clock jumps "
    << c.clock_jumps << ", satellites decided " << c.satellites << ", largest statistic clock "
    << c.max_clock_statistic << " satellites " << c.max_satellite_statistic;
  return s.str();
}

}  // namespace navbus::fault_manager
