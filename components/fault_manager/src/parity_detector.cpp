#include "navbus/fault_manager/parity_detector.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/conversions.hpp"
#include "navbus/core/math/units.hpp"

namespace navbus::fault_manager {

namespace {

using core::ImuInstrument;

constexpr const char* kKindNames[core::kImuInstrumentKinds] = {"gyro", "accelerometer"};

const char* kindName(ImuInstrument k) {
  return kKindNames[static_cast<int>(k)];
}

/// A bias in the unit a reader of that kind expects: deg/h for gyros, ug for accelerometers.
double readable(ImuInstrument k, double si) {
  return k == ImuInstrument::kGyro ? si / units::kDegPerHour : si / units::kMicroG;
}

const char* readableUnit(ImuInstrument k) {
  return k == ImuInstrument::kGyro ? "deg/h" : "ug";
}

navbus::FaultSource source(ImuInstrument k) {
  return k == ImuInstrument::kGyro ? navbus::SOURCE_GYRO : navbus::SOURCE_ACCELEROMETER;
}

}  // namespace

ParityDetector::ParityDetector(const ParityDetectorConfig& config)
    : config_(config),
      period_ns_(std::llround(1e9 / config.imu_rate_hz)),
      aligner_(static_cast<int>(config.units.size()),
               static_cast<std::size_t>(config.alignment_depth)) {
  makeArray();
  spdlog::info("parity detector: {} IMU units, {}", config_.units.size(),
               minimumDetectableBiases());
}

int ParityDetector::unitOf(std::uint32_t sensor_id) const {
  for (std::size_t u = 0; u < config_.sensor_ids.size(); ++u)
    if (config_.sensor_ids[u] == sensor_id) return static_cast<int>(u);
  return -1;
}

void ParityDetector::onIncrement(const navbus::ImuIncrement& msg, FaultOutput& out) {
  const int unit = unitOf(msg.sensor_id());
  if (unit < 0) {
    ++counters_.other_sensors;
    return;
  }
  if (bus::validate(msg, limits_)) {
    ++counters_.invalid;  // its time waits in vain and is dropped as incomplete
    return;
  }
  if (std::llabs(static_cast<long long>(msg.interval_ns()) - period_ns_) > 1) {
    if (counters_.wrong_interval++ == 0)
      spdlog::warn("parity detector: IMU {} increments over {} ns, configured {} Hz: not used",
                   msg.sensor_id(), msg.interval_ns(), config_.imu_rate_hz);
    return;
  }
  const auto time_ns = static_cast<std::int64_t>(msg.time_gps_ns());
  const auto u = static_cast<std::size_t>(unit);
  // A unit's reliable reader delivers its writer's increments in order: time and sequence both
  // going back is a new run of its source, not a late sample.
  if (msg.seq() < latest_seq_[u] && time_ns < aligner_.latestNs(unit)) startNewRun();
  if (latest_seq_[u] == 0 && msg.seq() > 1) noteMissedStart(msg);
  latest_seq_[u] = msg.seq();
  if (aligner_.add(unit, bus::toCore(msg)) != bus::ImuUnitAligner::Added::kTaken) {
    ++counters_.late;  // at or before a time already tested or dropped, or the same unit twice
    return;
  }
  ++counters_.increments;
  drain(out);
}

void ParityDetector::noteMissedStart(const navbus::ImuIncrement& first) {
  counters_.missed_at_start += first.seq() - 1;
  spdlog::warn(
      "parity detector: IMU {}'s first increment taken is number {}: the {} before it were not "
      "received (this reader joined after the unit's stream began); their times are tested "
      "without it",
      first.sensor_id(), first.seq(), first.seq() - 1);
}

void ParityDetector::makeArray() {
  std::string error;
  array_ = core::ImuArrayParity::make(config_.units, 1e-9 * static_cast<double>(period_ns_),
                                      config_.array, error);
  if (!array_) throw bus::ConfigError("configuration parity: " + error);
}

void ParityDetector::startNewRun() {
  makeArray();  // as configured (it was made so once: it cannot fail now)
  aligner_.clear();
  ended_units_ = 0;
  last_tested_ns_ = -1;
  latest_seq_.fill(0);
  latest_ = {};
  ++counters_.new_runs;
  spdlog::warn(
      "parity detector: the IMUs restarted at an earlier time: new run {} (the test "
      "starts over, every instrument in the array)",
      counters_.new_runs);
}

bool ParityDetector::onUnitEnded(std::uint32_t sensor_id) {
  const int unit = unitOf(sensor_id);
  if (unit >= 0) ended_units_ |= 1u << static_cast<unsigned>(unit);
  return ended_units_ == (1u << static_cast<unsigned>(array_->units())) - 1u;
}

void ParityDetector::drain(FaultOutput& out) {
  while (const std::optional<bus::ImuUnitAligner::Sample> sample = aligner_.next()) {
    if (!aligner_.complete(*sample)) {
      // A unit's increment lost, or a silent unit held alignment_depth times waiting.
      ++counters_.incomplete;
      array_->restart();  // the window's sums need consecutive samples
      last_tested_ns_ = -1;
      continue;
    }
    test(sample->time_ns, sample->units, out);
  }
}

void ParityDetector::test(std::int64_t time_ns, const bus::ImuUnitAligner::Increments& units,
                          FaultOutput& out) {
  if (last_tested_ns_ >= 0 && time_ns - last_tested_ns_ != period_ns_) {
    ++counters_.gaps;  // the window's sums need consecutive samples
    array_->restart();
  }
  last_tested_ns_ = time_ns;
  ++counters_.samples;
  latest_ = array_->update(units);
  for (int k = 0; k < core::kImuInstrumentKinds; ++k) {
    const auto i = static_cast<std::size_t>(k);
    counters_.max_statistic[i] = std::max(counters_.max_statistic[i], latest_.statistic[i]);
    if (latest_.detections[i]) report(time_ns, *latest_.detections[i], out);
  }
}

void ParityDetector::report(std::int64_t time_ns, const core::ImuArrayDetection& det,
                            FaultOutput& out) {
  const core::ParityGlrResult& r = det.glr;
  const bool ambiguous = r.ambiguous && det.runner_up_unit >= 0;
  navbus::FaultDecision d;
  d.time_gps_ns(static_cast<std::uint64_t>(time_ns));
  d.event(navbus::EVENT_FAULT_DETECTED);
  d.source(source(det.kind));
  d.sensor_id(config_.sensor_ids[static_cast<std::size_t>(det.unit)]);
  d.axis(static_cast<std::uint16_t>(det.axis));
  d.shape(navbus::SHAPE_STEP);
  d.test_statistic(r.statistic);
  d.threshold(r.threshold);
  d.magnitude(det.magnitude);
  // The first faulty sample is the onset's: the fault began after the sample before it.
  d.onset_time_gps_ns(static_cast<std::uint64_t>(time_ns - r.samples_since_onset * period_ns_));
  d.ambiguous(ambiguous);
  d.detector("parity");
  navbus::FaultCandidate best;
  best.source(d.source());
  best.sensor_id(d.sensor_id());
  best.axis(d.axis());
  best.shape(navbus::SHAPE_STEP);
  best.statistic(r.statistic);
  best.magnitude(det.magnitude);
  d.candidates().push_back(best);
  if (det.runner_up_unit >= 0) {
    navbus::FaultCandidate second = best;
    second.sensor_id(config_.sensor_ids[static_cast<std::size_t>(det.runner_up_unit)]);
    second.axis(static_cast<std::uint16_t>(det.runner_up_axis));
    second.magnitude(det.runner_up_magnitude);
    d.candidates().push_back(second);
  }
  const std::uint32_t id = out.decide(d);
  ++counters_.detections;
  if (ambiguous) ++counters_.ambiguous;
  spdlog::warn(
      "decision {}: parity {} IMU {} axis {}{} bias {:.4g} {} (+- {:.2g}), l {:.4g} >= h {:.4g}, "
      "onset {:.3f} s before",
      id, kindName(det.kind), d.sensor_id(), "xyz"[det.axis],
      ambiguous ? fmt::format(" or IMU {} axis {} (cannot be told apart)",
                              d.candidates()[1].sensor_id(), "xyz"[det.runner_up_axis])
                : std::string(),
      readable(det.kind, det.magnitude), readableUnit(det.kind),
      readable(det.kind, det.magnitude_sigma), r.statistic, r.threshold,
      1e-9 * static_cast<double>(r.samples_since_onset * period_ns_));
  // The instruments decided leave the test (the others go on while they have parity).
  bool still = array_->exclude(det.kind, det.unit, det.axis);
  if (ambiguous) still = array_->exclude(det.kind, det.runner_up_unit, det.runner_up_axis);
  if (!still)
    spdlog::warn("parity detector: the {}s left have no parity: {} detection stops",
                 kindName(det.kind), kindName(det.kind));
  if (!config_.fail_axes) return;
  navbus::FilterCommand c = failAxisCommand(d);  // decide() stamped its id
  if (ambiguous) {
    suspects_[d.decision_id()] = d;
    if (suspects_.size() > kSuspectsKept) suspects_.erase(suspects_.begin());
    // Which one: not ours to say. Both are suspects: each one's lane re-learns that bias from
    // the onset (its variance grows to the size found), and the filter's lanes compare their
    // estimates since the onset and leave the one that moved (or that fails its own test).
    for (const auto kind : {navbus::CMD_RELEARN_BIAS, navbus::CMD_SUSPECT_SENSOR_AXIS}) {
      c.kind(kind);
      c.bias(0.0);
      c.bias_sigma(kind == navbus::CMD_RELEARN_BIAS
                       ? std::max(std::abs(det.magnitude), 3.0 * det.magnitude_sigma)
                       : 0.0);
      for (const navbus::FaultCandidate& candidate : d.candidates()) {
        c.sensor_id(candidate.sensor_id());
        c.axis(candidate.axis());
        out.command(c);
        ++counters_.commands;
      }
    }
    return;
  }
  out.command(c);
  ++counters_.commands;
}

void ParityDetector::onLaneSolution(const navbus::LaneSolution& lane, FaultOutput& out) {
  const auto it = suspects_.find(lane.named_faulty_for_decision());
  if (it == suspects_.end()) return;  // none named, or named already
  const navbus::FaultDecision ambiguous = it->second;
  const auto& c = ambiguous.candidates();
  const bool first = c[0].sensor_id() == lane.lane_id();
  if (!first && c[1].sensor_id() != lane.lane_id()) return;  // not a candidate: not this one's
  suspects_.erase(it);
  navbus::FaultDecision d = ambiguous;
  const navbus::FaultCandidate& named = c[first ? 0 : 1];
  d.time_gps_ns(lane.solution().time_gps_ns());
  d.sensor_id(named.sensor_id());
  d.axis(named.axis());
  d.magnitude(named.magnitude());
  d.ambiguous(false);
  d.detector("lanes");
  d.candidates({named, c[first ? 1 : 0]});
  const std::uint32_t id = out.decide(d);
  ++counters_.named_by_lanes;
  const ImuInstrument kind =
      named.source() == navbus::SOURCE_GYRO ? ImuInstrument::kGyro : ImuInstrument::kAccelerometer;
  spdlog::warn(
      "decision {}: the lanes name IMU {} {} axis {} of decision {} at {:.3f} s (their "
      "estimates since the onset), bias {:.4g} {}",
      id, named.sensor_id(), kindName(kind), "xyz"[named.axis()], ambiguous.decision_id(),
      1e-9 * static_cast<double>(lane.solution().time_gps_ns()), readable(kind, named.magnitude()),
      readableUnit(kind));
}

std::string ParityDetector::minimumDetectableBiases() const {
  std::ostringstream s;
  const core::ImuArrayParity& a = *array_;
  for (int k = 0; k < core::kImuInstrumentKinds; ++k) {
    const auto kind = static_cast<ImuInstrument>(k);
    if (k > 0) s << "; ";
    s << kindName(kind) << "s: " << a.instruments(kind) << " axes, h " << a.threshold(kind)
      << ", minimum detectable bias (" << config_.array.glr.detection_probability
      << " probability over a " << config_.array.glr.onsets * config_.array.glr.onset_spacing
      << "-sample window) [" << readableUnit(kind) << "]";
    for (int u = 0; u < a.units(); ++u) {
      s << " IMU " << config_.sensor_ids[static_cast<std::size_t>(u)];
      for (int axis = 0; axis < 3; ++axis)
        s << (axis == 0 ? " " : "/")
          << fmt::format("{:.3g}", readable(kind, a.minimumDetectableBias(kind, u, axis)));
    }
  }
  return s.str();
}

std::string ParityDetector::summary() const {
  const Counters& c = counters_;
  std::ostringstream s;
  s << "parity: " << c.samples << " aligned samples of " << array_->units() << " IMUs ("
    << c.increments << " increments), detections " << c.detections << " (ambiguous " << c.ambiguous
    << ", commands " << c.commands << ", named by the lanes " << c.named_by_lanes
    << "), largest statistic gyros " << c.max_statistic[0] << " accelerometers "
    << c.max_statistic[1] << " (h " << array_->threshold(ImuInstrument::kGyro) << " / "
    << array_->threshold(ImuInstrument::kAccelerometer) << ")";
  if (c.other_sensors + c.invalid + c.wrong_interval + c.late + c.incomplete + c.gaps +
          c.missed_at_start >
      0)
    s << "; not used: other IMUs " << c.other_sensors << ", invalid " << c.invalid
      << ", other interval " << c.wrong_interval << ", late or repeated " << c.late
      << ", times without every unit " << c.incomplete << ", gaps " << c.gaps
      << ", not received before a unit's first " << c.missed_at_start;
  if (c.new_runs > 0) s << "; new runs after a source restart " << c.new_runs;
  return s.str();
}

}  // namespace navbus::fault_manager
