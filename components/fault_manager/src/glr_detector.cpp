#include "navbus/fault_manager/glr_detector.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <spdlog/spdlog.h>

#include "navbus/bus/conversions.hpp"

namespace navbus::fault_manager {

namespace {

navbus::FaultSource toSource(core::GlrFault f) {
  switch (f) {
    case core::GlrFault::kAccelStep:
      return navbus::SOURCE_ACCELEROMETER;
    case core::GlrFault::kGyroStep:
      return navbus::SOURCE_GYRO;
    default:
      return navbus::SOURCE_SATELLITE;
  }
}

navbus::FaultShape toShape(core::GlrFault f) {
  return f == core::GlrFault::kRangeRamp ? navbus::SHAPE_RAMP : navbus::SHAPE_STEP;
}

navbus::FaultCandidate toIdl(const core::GlrCandidate& c) {
  navbus::FaultCandidate out;
  out.source(toSource(c.hypothesis.fault));
  out.sv_id(static_cast<std::uint16_t>(c.hypothesis.sv_id));
  out.axis(static_cast<std::uint16_t>(c.hypothesis.isImu() ? c.hypothesis.axis : 0));
  out.shape(toShape(c.hypothesis.fault));
  if (!c.hypothesis.isImu() && c.hypothesis.receiver != core::GlrHypothesis::kEveryReceiver)
    out.sensor_id(static_cast<std::uint32_t>(c.hypothesis.receiver));  // one receiver's rows
  out.statistic(c.statistic);
  out.magnitude(c.magnitude);
  return out;
}

const char* axisName(int axis) {
  return axis == 0 ? "x" : axis == 1 ? "y" : "z";
}

std::string describe(const core::GlrCandidate& c) {
  std::ostringstream s;
  if (c.hypothesis.isImu()) {
    s << (c.hypothesis.fault == core::GlrFault::kAccelStep ? "accelerometer " : "gyro ")
      << axisName(c.hypothesis.axis) << " step";
  } else {
    s << "sv " << c.hypothesis.sv_id << " " << core::glrFaultName(c.hypothesis.fault);
    if (c.hypothesis.receiver != core::GlrHypothesis::kEveryReceiver)
      s << " at receiver " << c.hypothesis.receiver;
  }
  s << " (l* " << c.statistic << ", magnitude " << c.magnitude << ")";
  return s.str();
}

}  // namespace

bool GlrDetector::Quarantine::covers(int sv, bool is_rate) const {
  if (sv != sv_id) return false;
  return scope == navbus::SCOPE_ALL ||
         (is_rate ? scope == navbus::SCOPE_PSEUDORANGE_RATE : scope == navbus::SCOPE_PSEUDORANGE);
}

GlrDetector::GlrDetector(const GlrDetectorConfig& config)
    : config_(config), repeats_(config.repeats), glr_(config.glr) {
  quarantine_.reserve(32);
}

bool GlrDetector::onDiagnostics(const navbus::FilterDiagnostics& msg, FaultOutput& out) {
  if (!config_.enabled) return true;
  if (auto r = bus::toGlrEpoch(msg, epoch_)) {
    ++counters_.refused;
    spdlog::warn("glr: diagnostics seq {} refused: {}", msg.seq(), r->describe());
    return false;
  }
  if (last_seq_ != 0 && msg.seq() != last_seq_ + 1) {
    // A lost or repeated epoch breaks the signature recursion: start a new window.
    ++counters_.restarts;
    glr_.reset();
  }
  last_seq_ = msg.seq();
  checkReadmission(out);
  removeQuarantinedRows();
  const core::GlrResult& r = glr_.update(epoch_);
  if (!r.valid) {
    ++counters_.refused;
    return false;
  }
  ++counters_.epochs;
  latest_ = {epoch_.time_ns, r.statistic, r.threshold, r.onset_epochs_ago, r.detected};
  counters_.max_statistic = std::max(counters_.max_statistic, r.statistic);
  if (pending_.active) {
    refine(out);  // a detected IMU fault is being sized: no new decision meanwhile
  } else if (r.detected) {
    report(r, out);
  }
  return true;
}

navbus::FaultDecision GlrDetector::decision(const core::GlrResult& r) const {
  const core::GlrCandidate& best = r.candidates[0];
  navbus::FaultDecision d;
  d.time_gps_ns(static_cast<std::uint64_t>(epoch_.time_ns));
  d.event(navbus::EVENT_FAULT_DETECTED);
  const navbus::FaultCandidate isolated = toIdl(best);  // the decision names candidate 0
  d.source(isolated.source());
  d.sv_id(isolated.sv_id());
  d.sensor_id(isolated.sensor_id());
  d.axis(isolated.axis());
  d.shape(isolated.shape());
  d.test_statistic(r.statistic);
  d.threshold(r.threshold);
  d.magnitude(best.magnitude);
  d.onset_time_gps_ns(static_cast<std::uint64_t>(std::max<std::int64_t>(r.onset_time_ns, 0)));
  d.ambiguous(r.ambiguous || r.onset_censored);
  for (int i = 0; i < r.candidate_count; ++i)
    d.candidates().push_back(toIdl(r.candidates[static_cast<std::size_t>(i)]));
  d.detector("glr");
  return d;
}

void GlrDetector::report(const core::GlrResult& r, FaultOutput& out) {
  ++counters_.detections;
  const core::GlrCandidate& best = r.candidates[0];
  std::vector<FaultSourceKey> sources;
  for (int i = 0; i < std::min(r.candidate_count, 2); ++i) {
    const navbus::FaultCandidate c = toIdl(r.candidates[static_cast<std::size_t>(i)]);
    sources.push_back({static_cast<int>(c.source()), c.sv_id(), c.axis()});
  }
  const RepeatGuard::Verdict verdict = repeats_.onDetection(epoch_.time_ns, sources);
  if (verdict == RepeatGuard::Verdict::kSuppress) {
    ++counters_.suppressed;
    glr_.reset();
    return;
  }
  navbus::FaultDecision d = decision(r);
  const std::uint32_t id = out.decide(d);
  spdlog::warn("glr decision {}: {}{} at {:.3f} s, onset after {:.3f} s, l {:.1f} >= h {:.1f}", id,
               describe(best),
               r.ambiguous ? " or " + describe(r.candidates[1]) + " (ambiguous)" : "",
               1e-9 * static_cast<double>(epoch_.time_ns),
               1e-9 * static_cast<double>(r.onset_time_ns), r.statistic, r.threshold);

  navbus::FilterCommand c;
  c.decision_id(id);
  c.time_gps_ns(d.time_gps_ns());
  c.onset_time_gps_ns(d.onset_time_gps_ns());
  if (verdict == RepeatGuard::Verdict::kEscalate) {
    escalate(r, c, out);
  } else if (r.source == core::GlrSourceClass::kSatellite && config_.exclude_satellites) {
    // Only the faulty measurement: a code fault (pseudorange step or ramp) leaves the rate
    // in use, a rate fault the pseudorange.
    const navbus::SatelliteScope scope = best.hypothesis.fault == core::GlrFault::kRateStep
                                             ? navbus::SCOPE_PSEUDORANGE_RATE
                                             : navbus::SCOPE_PSEUDORANGE;
    c.kind(navbus::CMD_EXCLUDE_SATELLITE);
    c.sv_id(d.sv_id());
    c.scope(scope);
    out.command(c);
    glr_.setQuarantined(best.hypothesis.sv_id, true);
    quarantine_.push_back({best.hypothesis.sv_id, scope, -1, false});
    ++counters_.satellites_excluded;
  } else if (r.source == core::GlrSourceClass::kImu && (r.ambiguous || r.onset_censored) &&
             config_.compensate_imu) {
    // Which sensor cannot be told with the data at hand (seed 000: x-accelerometer and y-gyro
    // in straight flight), or the fault began before the window: no magnitude to trust.
    // Compensating the wrong sensor would add a second fault; instead the filter re-learns
    // the candidates' biases from the onset (their variances grow by the candidate's size).
    relearn(r, c, out);
  } else if (r.source == core::GlrSourceClass::kImu && config_.compensate_imu) {
    // The magnitude at first detection rests on a few epochs: keep accumulating at this onset
    // until it is precise (the filter restores itself to the onset, so waiting costs nothing).
    pending_ = Pending{true, id, r.onset_time_ns};
    refine(out);
    return;
  }
  // The filter reconfigures: signatures of the old configuration no longer describe it.
  glr_.reset();
}

void GlrDetector::keepOut(int sv_id) {
  const bool kept =
      std::any_of(quarantine_.begin(), quarantine_.end(), [sv_id](const Quarantine& q) {
        return q.permanent && q.covers(sv_id, false) && q.covers(sv_id, true);
      });
  if (kept) return;
  glr_.setQuarantined(sv_id, true);
  quarantine_.push_back({sv_id, navbus::SCOPE_ALL, -1, true});
  glr_.reset();
}

void GlrDetector::escalate(const core::GlrResult& r, navbus::FilterCommand c, FaultOutput& out) {
  ++counters_.escalated;
  spdlog::warn(
      "glr decision {}: the same source decided {} times within {:.0f} s: escalated "
      "(IMU axes failed, a satellite kept excluded); not decided again",
      c.decision_id(), config_.repeats.escalate_after + 1, config_.repeats.window_s);
  for (int i = 0; i < std::min(r.candidate_count, 2); ++i) {
    const core::GlrCandidate& cand = r.candidates[static_cast<std::size_t>(i)];
    if (toIdl(cand).source() == navbus::SOURCE_SATELLITE) {
      if (!config_.exclude_satellites) continue;
      c.kind(navbus::CMD_EXCLUDE_SATELLITE);
      c.sv_id(static_cast<std::uint16_t>(cand.hypothesis.sv_id));
      c.scope(navbus::SCOPE_ALL);
      out.command(c);
      glr_.setQuarantined(cand.hypothesis.sv_id, true);
      quarantine_.push_back({cand.hypothesis.sv_id, navbus::SCOPE_ALL, -1, true});
    } else if (config_.compensate_imu) {
      c.kind(navbus::CMD_FAIL_SENSOR_AXIS);
      c.sensor(toSource(cand.hypothesis.fault));
      c.axis(static_cast<std::uint16_t>(cand.hypothesis.axis));
      out.command(c);
    }
  }
}

void GlrDetector::relearn(const core::GlrResult& r, navbus::FilterCommand c, FaultOutput& out) {
  ++counters_.ambiguous;
  for (int i = 0; i < std::min(r.candidate_count, 2); ++i) {
    const core::GlrCandidate& cand = r.candidates[static_cast<std::size_t>(i)];
    c.kind(navbus::CMD_RELEARN_BIAS);
    c.sensor(toSource(cand.hypothesis.fault));
    c.axis(static_cast<std::uint16_t>(cand.hypothesis.axis));
    c.bias(0.0);
    c.bias_sigma(std::max(std::abs(cand.magnitude), 3.0 * cand.magnitude_sigma));
    out.command(c);
  }
}

void GlrDetector::refine(FaultOutput& out) {
  if (!pending_.active) return;
  // The onset may move by an epoch or two as data accumulate: the most likely IMU onset
  // within two epochs of the detected one.
  int age = glr_.onsetAge(pending_.onset_ns);
  core::GlrResult r = glr_.isolationAt(age);
  for (int a = std::max(age - 2, 0); age >= 0 && a <= age + 2; ++a) {
    const core::GlrResult other = glr_.isolationAt(a);
    if (other.valid && other.imu_statistic > r.imu_statistic) {
      r = other;
      age = a;
    }
  }
  const bool last_chance = age < 0 || age + 1 >= glr_.config().window;
  if (age >= 0 && r.source == core::GlrSourceClass::kImu) {
    last_ = r;
    pending_.onset_ns = r.onset_time_ns;
  }
  const core::GlrCandidate& best = last_.candidates[0];
  const bool precise =
      best.magnitude_sigma <= config_.compensation_relative_sigma * std::abs(best.magnitude);
  if (!precise && !last_chance) return;
  pending_.active = false;
  navbus::FilterCommand c;
  c.decision_id(pending_.decision_id);
  c.time_gps_ns(static_cast<std::uint64_t>(epoch_.time_ns));
  c.onset_time_gps_ns(static_cast<std::uint64_t>(std::max<std::int64_t>(pending_.onset_ns, 0)));
  if (last_.source != core::GlrSourceClass::kImu || last_.ambiguous || last_.onset_censored) {
    spdlog::warn(
        "glr decision {}: refined isolation is not certain: the filter re-learns the "
        "candidates' biases",
        pending_.decision_id);
    relearn(last_, c, out);
  } else {
    c.kind(navbus::CMD_COMPENSATE_BIAS);
    c.sensor(toSource(best.hypothesis.fault));
    c.axis(static_cast<std::uint16_t>(best.hypothesis.axis));
    c.bias(best.magnitude);
    c.bias_sigma(best.magnitude_sigma);
    out.command(c);
    ++counters_.biases_compensated;
    spdlog::warn("glr decision {}: compensating {} (+- {:.3g})", pending_.decision_id,
                 describe(best), best.magnitude_sigma);
  }
  glr_.reset();
}

void GlrDetector::removeQuarantinedRows() {
  // An excluded satellite's rows stay in the diagnostics (monitored, zero gain) for the
  // readmission test, but its fault would leak into every other hypothesis through the
  // correlations of V: the GLR sees the epoch without them.
  if (quarantine_.empty()) return;
  core::GlrEpoch& e = epoch_;
  std::array<int, core::glr::kMaxRows> keep{};
  int n = 0;
  for (int r = 0; r < e.rows; ++r) {
    const int sv = e.sv_id[static_cast<std::size_t>(r)];
    const bool rate = e.is_rate[static_cast<std::size_t>(r)];
    const bool excluded =
        std::any_of(quarantine_.begin(), quarantine_.end(),
                    [sv, rate](const Quarantine& q) { return q.covers(sv, rate); });
    if (!excluded) keep[static_cast<std::size_t>(n++)] = r;
  }
  if (n == e.rows) return;
  for (int i = 0; i < n; ++i) {
    const int r = keep[static_cast<std::size_t>(i)];
    e.sv_id[static_cast<std::size_t>(i)] = e.sv_id[static_cast<std::size_t>(r)];
    e.is_rate[static_cast<std::size_t>(i)] = e.is_rate[static_cast<std::size_t>(r)];
    e.receiver[static_cast<std::size_t>(i)] = e.receiver[static_cast<std::size_t>(r)];
    e.innovation[i] = e.innovation[r];
    e.h.row(i) = e.h.row(r);
    e.k.col(i) = e.k.col(r);
    for (int j = 0; j < n; ++j) {
      e.innovation_cov(i, j) = e.innovation_cov(r, keep[static_cast<std::size_t>(j)]);
    }
  }
  e.rows = n;
  e.innovation.conservativeResize(n);
  e.innovation_cov.conservativeResize(n, n);
  e.h.conservativeResize(n, Eigen::NoChange);
  e.k.conservativeResize(Eigen::NoChange, n);
}

void GlrDetector::checkReadmission(FaultOutput& out) {
  const std::int64_t now = epoch_.time_ns;
  for (auto it = quarantine_.begin(); it != quarantine_.end();) {
    bool seen = false, passing = true;
    for (int r = 0; r < epoch_.rows; ++r) {
      if (!it->covers(epoch_.sv_id[static_cast<std::size_t>(r)],
                      epoch_.is_rate[static_cast<std::size_t>(r)]))
        continue;
      seen = true;
      const double z = std::abs(epoch_.innovation[r]) / std::sqrt(epoch_.innovation_cov(r, r));
      passing = passing && z <= config_.readmit_sigma;
    }
    if (it->permanent || !seen || !passing) {
      it->passing_since_ns = -1;
      ++it;
      continue;
    }
    if (it->passing_since_ns < 0) it->passing_since_ns = now;
    if (1e-9 * static_cast<double>(now - it->passing_since_ns) < config_.readmit_after_s) {
      ++it;
      continue;
    }
    navbus::FaultDecision d;
    d.time_gps_ns(static_cast<std::uint64_t>(now));
    d.event(navbus::EVENT_FAULT_CLEARED);
    d.source(navbus::SOURCE_SATELLITE);
    d.sv_id(static_cast<std::uint16_t>(it->sv_id));
    d.threshold(config_.readmit_sigma);
    d.onset_time_gps_ns(static_cast<std::uint64_t>(it->passing_since_ns));
    d.detector("glr");
    const std::uint32_t id = out.decide(d);
    navbus::FilterCommand c;
    c.kind(navbus::CMD_READMIT_SATELLITE);
    c.decision_id(id);
    c.time_gps_ns(d.time_gps_ns());
    c.sv_id(d.sv_id());
    c.scope(it->scope);
    out.command(c);
    spdlog::info("glr decision {}: sv {} passes again since {:.3f} s: readmitted", id, it->sv_id,
                 1e-9 * static_cast<double>(it->passing_since_ns));
    glr_.setQuarantined(it->sv_id, false);
    ++counters_.readmitted;
    it = quarantine_.erase(it);
  }
}

std::string GlrDetector::summary() const {
  const Counters& c = counters_;
  std::ostringstream s;
  s << "glr: epochs " << c.epochs << ", refused " << c.refused << ", restarts " << c.restarts
    << ", detections " << c.detections << " (satellites excluded " << c.satellites_excluded
    << ", biases compensated " << c.biases_compensated << ", ambiguous " << c.ambiguous
    << "), readmitted " << c.readmitted << ", repeated decisions escalated " << c.escalated
    << " (detections not decided again " << c.suppressed << "), max statistic " << c.max_statistic;
  return s.str();
}

}  // namespace navbus::fault_manager
