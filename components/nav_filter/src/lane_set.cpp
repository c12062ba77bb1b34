#include "navbus/nav_filter/lane_set.hpp"

#include <algorithm>
#include <limits>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <Eigen/Geometry>

#include "navbus/bus/conversions.hpp"
#include "navbus/core/math/earth.hpp"

namespace navbus::nav_filter {

namespace {

/// The configuration of the lane of `unit`: its IMU, its mounting, the antenna seen from it.
/// Lanes after the first do not run the low-latency output.
FilterConfig laneConfig(const FilterConfig& base, const LaneUnit& unit, bool first) {
  FilterConfig c = base;
  c.lanes = {};
  c.imu.id = unit.sensor_id;
  c.imu_mounting.sensor_to_body = unit.c_b_u;
  c.engine.antenna_lever_arm_b_m = base.engine.antenna_lever_arm_b_m - unit.lever_arm_b_m;
  c.engine.second_antenna_lever_arm_b_m =
      base.engine.second_antenna_lever_arm_b_m - unit.lever_arm_b_m;
  if (!first) c.low_latency_output = false;
  return c;
}

/// The configuration with the selection's preferred lane: the least-squares lane (after the
/// units' lanes) when `lanes.least_squares.preferred`.
FilterConfig withPreferredLane(FilterConfig c) {
  if (c.lanes.least_squares_lane_id && c.lanes.least_squares_preferred)
    c.lanes.selector.preferred = static_cast<int>(c.lanes.units.size());
  return c;
}

core::ImuInstrument instrument(const navbus::FilterCommand& c) {
  return c.sensor() == navbus::SOURCE_ACCELEROMETER ? core::ImuInstrument::kAccelerometer
                                                    : core::ImuInstrument::kGyro;
}

bool isImuCommand(const navbus::FilterCommand& c) {
  switch (c.kind()) {
    case navbus::CMD_FAIL_SENSOR_AXIS:
    case navbus::CMD_RESTORE_SENSOR_AXIS:
    case navbus::CMD_COMPENSATE_BIAS:  // a receiver's clock: every lane fuses that receiver
      return c.sensor() != navbus::SOURCE_RECEIVER_CLOCK;
    case navbus::CMD_RELEARN_BIAS:
      return true;
    case navbus::CMD_EXCLUDE_STREAM:
    case navbus::CMD_READMIT_STREAM:
      return c.sensor() == navbus::SOURCE_IMU_STREAM;
    default:
      return false;
  }
}

/// The lane's solution (its IMU's place) moved to the body origin, r_b from it.
navbus::NavigationSolution atBodyOrigin(navbus::NavigationSolution s, const Eigen::Vector3d& r_b) {
  if (r_b.isZero()) return s;
  const core::NavState n = bus::toCore(s);
  const core::earth::Geodetic origin = core::earth::offsetNed(n.position, -(n.q_b_to_n * r_b));
  s.latitude_rad(origin.latitude_rad);
  s.longitude_rad(origin.longitude_rad);
  s.height_m(origin.height_m);
  const Eigen::Vector3d ecef = core::earth::geodeticToEcef(origin);
  for (int i = 0; i < 3; ++i) s.pos_ecef_m()[static_cast<std::size_t>(i)] = ecef[i];
  return s;
}

void setDelta(navbus::NavigationSolution& s, const core::LaneResetDelta& d) {
  for (std::size_t i = 0; i < 3; ++i) {
    s.reset_delta_pos_ned_m()[i] = d.position_ned_m[static_cast<Eigen::Index>(i)];
    s.reset_delta_vel_ned_mps()[i] = d.velocity_ned_mps[static_cast<Eigen::Index>(i)];
    s.reset_delta_att_ned_rad()[i] = d.attitude_ned_rad[static_cast<Eigen::Index>(i)];
  }
}

}  // namespace

LaneSet::LaneSet(const FilterConfig& config, bus::HealthCounters& health, Sinks sinks)
    : config_(withPreferredLane(config)),
      sinks_(std::move(sinks)),
      selector_(config_.lanes.selector),
      suspects_(config.lanes.units, config.lanes.evidence) {
  if (config_.lanes.units.empty()) {
    // One lane: the filter as configured, its solutions straight through.
    lanes_.push_back(std::make_unique<FilterPipeline>(config_, health, sinks_.filter));
    return;
  }
  const auto& units = config_.lanes.units;
  for (std::size_t k = 0; k < units.size(); ++k) {
    const bool first = k == 0;
    FilterPipeline::Sinks s;
    s.solution = [this, k](const navbus::NavigationSolution& sol) {
      onLaneSolution(static_cast<int>(k), sol);
    };
    if (first) {
      s.diagnostics = sinks_.filter.diagnostics;
      s.low_latency = sinks_.filter.low_latency;
    }
    // Every lane answers the commands it was given on its own (lane_set.hpp); lane 0 answers
    // the ones given to all.
    s.command_outcome = [this, k](const navbus::FilterCommandOutcome& o) {
      const bool own = routed_.erase({o.issuer().to_string(), o.run_id(), o.command_id()}) > 0;
      if ((k == 0 || own) && sinks_.filter.command_outcome) sinks_.filter.command_outcome(o);
    };
    if (!first)
      lane_health_.push_back(
          std::make_unique<bus::HealthCounters>("lane " + std::to_string(units[k].sensor_id)));
    bus::HealthCounters& h = first ? health : *lane_health_.back();
    // Each lane's own unit is counted in the participant's health under its id; what every
    // lane is fed is counted once, by the first.
    lanes_.push_back(
        std::make_unique<FilterPipeline>(laneConfig(config_, units[k], first), h, health, s));
    lane_units_.push_back(units[k]);
  }
  if (config_.lanes.least_squares_lane_id) addLeastSquaresLane();
  // A fault manager started with the filter (fault_monitor.judged_from_start) judges the
  // lanes' IMU data from the first sample: every lane and the selection wait for it from the
  // start, not only once it has reported (a replay as fast as the readers take would otherwise
  // run ahead of its first report and select before a decision it was owed).
  if (config_.fault_monitor && config_.fault_monitor->judged_from_start) {
    forEach([](FilterPipeline& l) { l.setImuJudged(); });
    parity_reported_ = true;
  }
  const std::size_t n = lanes_.size();
  pending_.resize(n);
  excluded_.assign(n, false);
  excluded_from_ns_.assign(n, std::numeric_limits<std::int64_t>::max());
  named_for_decision_.assign(n, 0);
  heard_ns_.assign(n, -1);
  previous_.assign(n, std::nullopt);
  statuses_.resize(n);
}

void LaneSet::addLeastSquaresLane() {
  combined_.emplace(config_);
  const std::size_t k = lanes_.size();
  FilterPipeline::Sinks s;
  s.solution = [this, k](const navbus::NavigationSolution& sol) {
    onLaneSolution(static_cast<int>(k), sol);
  };
  // Its own re-learns are answered to no one; a command routed to it alone, to its issuer.
  s.command_outcome = [this](const navbus::FilterCommandOutcome& o) {
    if (routed_.erase({o.issuer().to_string(), o.run_id(), o.command_id()}) > 0 &&
        sinks_.filter.command_outcome)
      sinks_.filter.command_outcome(o);
  };
  const std::uint32_t id = *config_.lanes.least_squares_lane_id;
  // Its IMU is no sensor of the bus: counted in its own health only.
  lane_health_.push_back(
      std::make_unique<bus::HealthCounters>("lane " + std::to_string(id) + " (least squares)"));
  lanes_.push_back(std::make_unique<FilterPipeline>(combined_->laneConfig(), *lane_health_.back(),
                                                    *lane_health_.back(), s));
  LaneUnit unit;  // body axes, at the body origin
  unit.sensor_id = id;
  lane_units_.push_back(unit);
}

void LaneSet::feedCombined(bool all) {
  // Not again from within: the lane's solutions select, which may come back here.
  if (!combined_ || feeding_) return;
  feeding_ = true;
  // A time is combined once the parity test has judged it and its commands are in (a failed
  // axis leaves the combination at its decision's time, on the bus as offline).
  std::int64_t judged =
      parity_reported_ ? parity_judged_ns_ : std::numeric_limits<std::int64_t>::max();
  // A judgement later than its wait (the fault manager's first report comes with its first
  // diagnostics, after the filter's alignment; a stopped fault manager) is not waited for
  // longer, as the lanes' merges do not: counted. A command about a time already combined then
  // takes its instrument out from the next time combined (offline, from its own).
  if (combined_->heldBeyond(judged)) {
    const std::int64_t wait_ns =
        config_.fault_monitor ? config_.fault_monitor->judgement_wait_ns : 0;
    if (combined_held_since_ns_ < 0) combined_held_since_ns_ = now_ns_;
    if (all || now_ns_ - combined_held_since_ns_ >= wait_ns) {
      if (!all) ++combined_unjudged_;
      judged = std::numeric_limits<std::int64_t>::max();
      combined_held_since_ns_ = -1;
    }
  } else {
    combined_held_since_ns_ = -1;
  }
  const std::size_t k = lanes_.size() - 1;
  FilterPipeline& lane = *lanes_[k];
  while (std::optional<CombinedImu::Output> out = combined_->next(judged, all)) {
    const auto t = static_cast<std::int64_t>(out->increment.time_gps_ns());
    for (const core::ImuInstrument kind :
         {core::ImuInstrument::kGyro, core::ImuInstrument::kAccelerometer}) {
      if (!out->relearn[static_cast<std::size_t>(kind)]) continue;
      for (int axis = 0; axis < 3; ++axis) lane.addOwnCommand(relearnCommand(kind, axis, t));
    }
    if (out->unusable) {
      excluded_[k] = true;
      excluded_from_ns_[k] = std::min(excluded_from_ns_[k], t);
    }
    lane.onImu(out->increment);
  }
  feeding_ = false;
}

navbus::FilterCommand LaneSet::relearnCommand(core::ImuInstrument kind, int axis,
                                              std::int64_t time_ns) {
  // The combination's bias changed with its weights by E' b' - E b: each instrument's bias
  // within its prior, so the lane re-learns within that prior.
  const core::FilterTuning& t = config_.engine.tuning;
  const bool gyro = kind == core::ImuInstrument::kGyro;
  navbus::FilterCommand c;
  c.command_id(++own_commands_);
  c.vehicle_id(config_.vehicle_id);
  c.kind(navbus::CMD_RELEARN_BIAS);
  c.time_gps_ns(static_cast<std::uint64_t>(time_ns));
  c.sensor(gyro ? navbus::SOURCE_GYRO : navbus::SOURCE_ACCELEROMETER);
  c.sensor_id(*config_.lanes.least_squares_lane_id);
  c.axis(static_cast<std::uint16_t>(axis));
  c.bias_sigma(gyro ? t.gyro_bias_sigma_radps : t.accel_bias_sigma_mps2);
  c.issuer("lanes");
  return c;
}

int LaneSet::laneOf(std::uint32_t sensor_id) const {
  const auto& units = config_.lanes.units;
  for (std::size_t k = 0; k < units.size(); ++k)
    if (units[k].sensor_id == sensor_id) return static_cast<int>(k);
  return -1;
}

void LaneSet::onImu(const navbus::ImuIncrement& msg) {
  // Another IMU's increment goes to lane 0, which refuses it as an unexpected source (counted).
  const int unit = laneOf(msg.sensor_id());
  lanes_[static_cast<std::size_t>(std::max(unit, 0))]->onImu(msg);
  if (combined_ && unit >= 0) {
    combined_->onIncrement(unit, msg);
    feedCombined(false);
  }
}

void LaneSet::onImuBlock(const navbus::ImuIncrementBlock& msg) {
  const int unit = laneOf(msg.sensor_id());
  lanes_[static_cast<std::size_t>(std::max(unit, 0))]->onImuBlock(msg);
  if (combined_ && unit >= 0 && msg.increments().size() > 0) {
    for (const navbus::ImuIncrement& inc : msg.increments())
      if (inc.sensor_id() == msg.sensor_id()) combined_->onIncrement(unit, inc);
    feedCombined(false);
  }
}

void LaneSet::onGnssObservations(const navbus::GnssObservationEpoch& msg) {
  forEach([&](FilterPipeline& l) { l.onGnssObservations(msg); });
}

void LaneSet::onGnssFix(const navbus::GnssFix& msg) {
  forEach([&](FilterPipeline& l) { l.onGnssFix(msg); });
}

void LaneSet::onStarTracker(const navbus::StarTrackerAttitude& msg) {
  forEach([&](FilterPipeline& l) { l.onStarTracker(msg); });
}

void LaneSet::onGnssObservationsBlock(const navbus::GnssObservationEpochBlock& msg) {
  forEach([&](FilterPipeline& l) { l.onGnssObservationsBlock(msg); });
}

void LaneSet::onGnssFixBlock(const navbus::GnssFixBlock& msg) {
  forEach([&](FilterPipeline& l) { l.onGnssFixBlock(msg); });
}

void LaneSet::onStarTrackerBlock(const navbus::StarTrackerAttitudeBlock& msg) {
  forEach([&](FilterPipeline& l) { l.onStarTrackerBlock(msg); });
}

void LaneSet::onStreamEnded(bus::StreamKind kind, std::uint32_t id) {
  if (kind != bus::StreamKind::kImu || lanes_.size() == 1) {
    forEach([&](FilterPipeline& l) { l.onStreamEnded(kind, id); });
    return;
  }
  // The lane still has what its merge holds to process: it is waited for until it has (or it
  // falls silent). Another IMU's end goes to lane 0, which logs it as not in use.
  const int k = laneOf(id);
  lanes_[static_cast<std::size_t>(std::max(k, 0))]->onStreamEnded(kind, id);
  if (combined_ && k >= 0) {
    combined_->unitEnded(k);
    feedCombined(false);
  }
}

void LaneSet::onFaultMonitorProgress(const navbus::FaultMonitorProgress& report) {
  if (lanes_.size() == 1 || report.vehicle_id() != config_.vehicle_id) {
    lanes_.front()->onFaultMonitorProgress(report);
    return;
  }
  if (report.imu_judged_up_to_gps_ns() == 0) {
    // No parity test (yet): the GLR's judgement concerns lane 0, the receivers' every lane.
    if (report.gnss_judged_up_to_gps_ns() == 0) {
      lanes_.front()->onFaultMonitorProgress(report);
    } else {
      forEach([&](FilterPipeline& l) { l.onFaultMonitorProgress(report); });
    }
    return;
  }
  // The parity test judges every lane's IMU data: each lane waits for it (lane 0 for it and for
  // the GLR's judgement of its diagnostics, whichever is behind), and so does the selection.
  if (!parity_reported_) forEach([](FilterPipeline& l) { l.setImuJudged(); });
  parity_reported_ = true;
  forEach([&](FilterPipeline& l) { l.onFaultMonitorProgress(report); });
  navbus::FaultMonitorProgress parity = report;
  parity.judged_up_to_gps_ns(report.imu_judged_up_to_gps_ns());
  if (const auto judged = parity_judgements_.onProgress(parity))
    parity_judged_ns_ = std::max(parity_judged_ns_, *judged);
  feedCombined(false);
  release(false);
}

void LaneSet::onCommand(const navbus::FilterCommand& c,
                        const std::optional<std::string>& writer_identity) {
  if (lanes_.size() == 1) return lanes_.front()->onCommand(c, writer_identity);
  if (const auto judged = parity_judgements_.onCommand(c))
    parity_judged_ns_ = std::max(parity_judged_ns_, *judged);
  if (c.kind() == navbus::CMD_SUSPECT_SENSOR_AXIS) {
    onSuspect(c, writer_identity);
    for (std::size_t k = 1; k < lanes_.size(); ++k) lanes_[k]->onCommandElsewhere(c);
    feedCombined(false);
    release(false);
    return;
  }
  if (!isImuCommand(c)) {
    forEach([&](FilterPipeline& l) { l.onCommand(c, writer_identity); });
    feedCombined(false);
    release(false);
    return;
  }
  // An IMU's command concerns its lane (sensor_id 0: the filter's own IMU, lane 0's); one for
  // an IMU without a lane goes to lane 0, which refuses it naming the id.
  const int named = laneOf(c.sensor_id() == 0 ? config_.imu.id : c.sensor_id());
  const auto k = static_cast<std::size_t>(std::max(named, 0));
  if (named > 0) routed_.insert({c.issuer().to_string(), c.run_id(), c.command_id()});
  if (named >= 0) {
    // A failed axis is a fact of the data (the decision's time). A stream declared lost is not
    // (a watchdog's wall-time judgement, which a stalled process may have made): the lane keeps
    // its place and is left only if it stops producing (MODE_INERTIAL_LOST, or silent).
    const bool out = c.kind() == navbus::CMD_FAIL_SENSOR_AXIS;
    const bool back = c.kind() == navbus::CMD_RESTORE_SENSOR_AXIS;
    if (out || back) excluded_[k] = out;
    if (out && combined_)
      combined_->exclude(instrument(c), named, c.axis(),
                         static_cast<std::int64_t>(c.time_gps_ns()));
    // Data time, not arrival: the lane is unavailable from the decision's time on.
    if (out) excluded_from_ns_[k] = static_cast<std::int64_t>(c.time_gps_ns());
    if (back) excluded_from_ns_[k] = std::numeric_limits<std::int64_t>::max();
  }
  lanes_[k]->onCommand(c, writer_identity);
  for (std::size_t other = 0; other < lanes_.size(); ++other)
    if (other != k) lanes_[other]->onCommandElsewhere(c);
  feedCombined(false);
  release(false);
}

void LaneSet::onSuspect(const navbus::FilterCommand& c,
                        const std::optional<std::string>& writer_identity) {
  FilterPipeline& first = *lanes_.front();
  if (!first.admitLanesCommand(c, writer_identity)) return;
  const int k = laneOf(c.sensor_id());
  const bool accel = c.sensor() == navbus::SOURCE_ACCELEROMETER;
  std::string why;
  if (k < 0)
    why = fmt::format("sensor_id {} has no lane (lanes.units)", c.sensor_id());
  else if (!accel && c.sensor() != navbus::SOURCE_GYRO)
    why = fmt::format("sensor {} is not an accelerometer or gyro", static_cast<int>(c.sensor()));
  else if (c.axis() > 2)
    why = fmt::format("axis {} outside 0..2", c.axis());
  if (!why.empty()) {
    first.answerLanesCommand(c, false, navbus::REJECT_OUT_OF_RANGE, why);
    spdlog::warn("command {} from '{}' refused: {}", c.command_id(), c.issuer(), why);
    return;
  }
  // The onset is where the comparison starts (the decision's time when none is given).
  const auto onset = static_cast<std::int64_t>(c.onset_time_gps_ns() > 0 ? c.onset_time_gps_ns()
                                                                         : c.time_gps_ns());
  const std::string noted = suspects_.onSuspect({c.decision_id(), k, accel, c.axis(), onset});
  // Either may be the faulty one: both leave the combination at the decision's time.
  if (combined_)
    combined_->exclude(instrument(c), k, c.axis(), static_cast<std::int64_t>(c.time_gps_ns()));
  first.answerLanesCommand(c, true, navbus::REJECT_NOT_APPLICABLE, {});
  spdlog::info("command {} from '{}': {}", c.command_id(), c.issuer(), noted);
}

void LaneSet::judgeSuspects(std::int64_t time_ns, const std::vector<const Pending*>& at) {
  // The units' lanes (the least-squares lane is no unit's: it has no part in the comparison).
  suspect_view_.assign(config_.lanes.units.size(), nullptr);
  for (std::size_t k = 0; k < suspect_view_.size(); ++k)
    if (at[k]) suspect_view_[k] = &at[k]->solution;
  const auto named = suspects_.atSelection(time_ns, suspect_view_);
  if (!named) return;
  // As a failed axis: unavailable from this data time on (the selection below leaves it).
  const auto k = static_cast<std::size_t>(named->suspect.lane);
  excluded_[k] = true;
  excluded_from_ns_[k] = std::min(excluded_from_ns_[k], time_ns);
  named_for_decision_[k] = named->suspect.decision_id;
}

void LaneSet::pump(std::int64_t now_ns) {
  feedCombined(false);
  now_ns_ = now_ns;
  for (std::int64_t& heard : heard_ns_)
    if (heard < 0) heard = now_ns;  // a lane's silence counts from the first turn
  forEach([&](FilterPipeline& l) { l.pump(now_ns); });
  if (lanes_.size() > 1) release(false);
}

void LaneSet::resumedAfterStall(std::int64_t now_ns, std::int64_t stalled_ns) {
  forEach([&](FilterPipeline& l) { l.resumedAfterStall(now_ns, stalled_ns); });
}

void LaneSet::setWritersAlive(bus::StreamKind kind, bool alive, std::int64_t now_ns) {
  forEach([&](FilterPipeline& l) { l.setWritersAlive(kind, alive, now_ns); });
}

void LaneSet::flush(std::int64_t now_ns) {
  feedCombined(true);
  forEach([&](FilterPipeline& l) { l.flush(now_ns); });
  if (lanes_.size() > 1) release(true);
}

void LaneSet::publishHeldSolution() {
  forEach([](FilterPipeline& l) { l.publishHeldSolution(); });
}

void LaneSet::setFaultMonitorAlive(bool alive) {
  forEach([&](FilterPipeline& l) { l.setFaultMonitorAlive(alive); });
}

void LaneSet::onLaneSolution(int k, const navbus::NavigationSolution& s) {
  const auto i = static_cast<std::size_t>(k);
  // A lane's silence counts from the first solution of any lane: before it, every lane waits
  // alike (for the fault manager's first judgement; judged_from_start).
  if (!any_heard_) heard_ns_.assign(heard_ns_.size(), now_ns_);
  any_heard_ = true;
  heard_ns_[i] = now_ns_;
  // The lane's fit as it stands at this solution (the engine moves on before the selection).
  Pending p{atBodyOrigin(s, lane_units_[i].lever_arm_b_m),
            lanes_[i]->engine().consistency().windowNisPerRow()};
  // A source restart reaches the lanes one by one: the first lane in a new run starts the
  // selection over; a lane still flushing the earlier run is heard out unselected.
  const std::uint64_t lane_run = lanes_[i]->newRuns();
  if (lane_run > run_) startNewRun(lane_run);
  if (lane_run < run_ || static_cast<std::int64_t>(s.time_gps_ns()) <= last_selected_ns_) {
    // Its time was selected without it (a lane failed by a command is not waited for, one
    // silent too long is passed over): not selected, but on the lanes topic all the same, as
    // offline, where no lane comes late, it is.
    ++late_;
    publishLane(i, p, false);
    return;
  }
  pending_[i].push_back(std::move(p));
  release(false);
}

void LaneSet::startNewRun(std::uint64_t run) {
  release(true);
  run_ = run;
  const std::size_t n = pending_.size();
  for (auto& lane : pending_) lane.clear();
  selector_ = core::LaneSelector(config_.lanes.selector);
  last_delta_ = {};
  previous_.assign(n, std::nullopt);
  excluded_.assign(n, false);
  excluded_from_ns_.assign(n, std::numeric_limits<std::int64_t>::max());
  named_for_decision_.assign(n, 0);
  parity_judgements_.newRun();
  suspects_.newRun();
  parity_judged_ns_ = -1;
  held_since_ns_ = -1;
  last_selected_ns_ = -1;
  solutions_earlier_runs_ += seq_;
  seq_ = 0;
  spdlog::warn(
      "lanes: the IMUs restarted at an earlier time: new run {} (the selection starts "
      "over)",
      run);
}

void LaneSet::release(bool all) {
  for (;;) {
    std::int64_t t = -1;
    std::size_t deepest = 0;
    for (const auto& lane : pending_) {
      deepest = std::max(deepest, lane.size());
      if (lane.empty()) continue;
      const auto front = static_cast<std::int64_t>(lane.front().solution.time_gps_ns());
      if (t < 0 || front < t) t = front;
    }
    if (t < 0) return;
    if (!all && missing(t)) {
      // A lane behind the others is waited for while it speaks (a lane holding for its fault
      // monitor's judgement lags, and is still right); one silent beyond the waits, or
      // max_pending solutions behind, is passed over at this time.
      if (!anySilentLaneMissing(t) && deepest <= config_.lanes.max_pending) return;
      ++passed_over_;  // the slow lane is unavailable at this time
    }
    if (!all && holdForParity(t)) return;
    select(t);
  }
}

bool LaneSet::missing(std::int64_t time_ns) const {
  // A lane failed at or before this time is not waited for (data time: the bus and offline
  // agree whenever the command arrives).
  for (std::size_t k = 0; k < pending_.size(); ++k)
    if (pending_[k].empty() && time_ns < excluded_from_ns_[k]) return true;
  return false;
}

bool LaneSet::anySilentLaneMissing(std::int64_t time_ns) const {
  // A lane may hold its output for its fault monitor's judgement: silent is longer than both.
  const std::int64_t wait_ns =
      std::max(config_.sequencer_max_wait_ns,
               config_.fault_monitor ? config_.fault_monitor->judgement_wait_ns : 0);
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    if (!pending_[k].empty() || time_ns >= excluded_from_ns_[k]) continue;
    if (heard_ns_[k] >= 0 && now_ns_ - heard_ns_[k] > wait_ns) return true;
  }
  return false;
}

bool LaneSet::holdForParity(std::int64_t time_ns) {
  if (!parity_reported_ || time_ns <= parity_judged_ns_) {
    held_since_ns_ = -1;
    return false;
  }
  const std::int64_t wait_ns =
      config_.fault_monitor ? config_.fault_monitor->judgement_wait_ns : 5'000'000'000;
  if (held_since_ns_ < 0) held_since_ns_ = now_ns_;
  if (now_ns_ - held_since_ns_ < wait_ns) return true;
  ++parity_waits_timed_out_;  // the monitor is silent: selected without its judgement
  held_since_ns_ = -1;
  parity_reported_ = false;  // and not waited for again until it reports
  return false;
}

bool LaneSet::available(int k, const Pending* p) const {
  if (!p) return false;
  if (static_cast<std::int64_t>(p->solution.time_gps_ns()) >=
      excluded_from_ns_[static_cast<std::size_t>(k)])
    return false;
  const navbus::NavigationSolution& s = p->solution;
  return s.covariance_valid() && s.mode() != navbus::MODE_ALIGNING &&
         s.mode() != navbus::MODE_INERTIAL_LOST;
}

void LaneSet::select(std::int64_t time_ns) {
  last_selected_ns_ = time_ns;
  std::vector<const Pending*>& at = at_;  // reused: no allocation per selection
  at.assign(pending_.size(), nullptr);
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    if (!pending_[k].empty() &&
        static_cast<std::int64_t>(pending_[k].front().solution.time_gps_ns()) == time_ns)
      at[k] = &pending_[k].front();
  }
  judgeSuspects(time_ns, at);
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    core::LaneStatus& st = statuses_[k];
    st.available = available(static_cast<int>(k), at[k]);
    st.test_ratio = at[k] ? at[k]->test_ratio : 0.0;
    if (at[k]) st.solution = bus::toCore(at[k]->solution);
  }
  const core::LaneSelection& sel = selector_.update(statuses_);
  if (sel.switched) {
    // The jump a consumer sees is from the old lane's last published solution to the new one's:
    // the lanes' difference at that last time, when the old lane was still as published (a lane
    // failed by a command changes at once: its rollback re-processes its data). Both lanes had
    // a solution then; otherwise their difference now.
    const auto from = static_cast<std::size_t>(sel.previous_lane);
    const auto to = static_cast<std::size_t>(sel.lane);
    last_delta_ = previous_[from] && previous_[to]
                      ? core::laneResetDelta(*previous_[from], *previous_[to])
                      : sel.delta;
    spdlog::warn(
        "lanes: switched from IMU {} to IMU {} at {:.3f} s ({}), reset {}: position "
        "{:.3f} m, velocity {:.4f} m/s, attitude {:.3g} mrad",
        lane_units_[static_cast<std::size_t>(sel.previous_lane)].sensor_id,
        lane_units_[static_cast<std::size_t>(sel.lane)].sensor_id,
        1e-9 * static_cast<double>(time_ns),
        sel.reason == core::LaneSwitchReason::kUnavailable ? "the lane became unavailable"
                                                           : "a clearly better fit",
        sel.reset_count, last_delta_.position_ned_m.norm(), last_delta_.velocity_ned_mps.norm(),
        1e3 * last_delta_.attitude_ned_rad.norm());
  }
  // Every lane's solution on its own instance; the selected one published.
  for (std::size_t k = 0; k < pending_.size(); ++k)
    if (at[k]) publishLane(k, *at[k], static_cast<int>(k) == sel.lane);
  if (sel.lane >= 0 && at[static_cast<std::size_t>(sel.lane)]) {
    navbus::NavigationSolution out = at[static_cast<std::size_t>(sel.lane)]->solution;
    out.seq(++seq_);
    out.reset_count(sel.reset_count);
    setDelta(out, last_delta_);
    sinks_.filter.solution(out);
  }
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    previous_[k] = at[k] ? std::optional<core::NavState>(statuses_[k].solution) : std::nullopt;
    if (at[k]) pending_[k].pop_front();
  }
}

void LaneSet::publishLane(std::size_t k, const Pending& p, bool selected) const {
  if (!sinks_.lane) return;
  navbus::LaneSolution l;
  l.vehicle_id(config_.vehicle_id);
  l.lane_id(lane_units_[k].sensor_id);
  l.selected(selected);
  l.available(available(static_cast<int>(k), &p));
  l.test_ratio(p.test_ratio);
  if (static_cast<std::int64_t>(p.solution.time_gps_ns()) >= excluded_from_ns_[k])
    l.named_faulty_for_decision(named_for_decision_[k]);
  l.solution(p.solution);
  sinks_.lane(l);
}

std::string LaneSet::summary() const {
  if (lanes_.size() == 1) return lanes_.front()->summary();
  std::ostringstream s;
  const core::LaneSelection& sel = selector_.last();
  s << "lanes: " << lanes_.size() << ", selected IMU "
    << (sel.lane >= 0 ? lane_units_[static_cast<std::size_t>(sel.lane)].sensor_id : 0)
    << ", switches " << sel.reset_count << ", solutions published " << seq_
    << ", times selected without a lane (silent beyond the sequencer's and the judgement's waits, "
    << "or " << config_.lanes.max_pending << " solutions behind) " << passed_over_
    << " (its solutions came later " << late_ << ")"
    << ", selections made without the parity test's judgement (its wait ran out) "
    << parity_waits_timed_out_;
  if (suspects_.counters().questions > 0) s << "; " << suspects_.summary();
  if (run_ > 0)
    s << ", new runs after a source restart " << run_ << " (solutions of earlier runs "
      << solutions_earlier_runs_ << ")";
  for (std::size_t k = 0; k < lanes_.size(); ++k)
    s << (k == 0 ? "; " : "\n") << "lane IMU " << lane_units_[k].sensor_id
      << (excluded_[k] ? " (excluded)" : "") << ": " << lanes_[k]->summary();
  if (combined_)
    s << "\n"
      << combined_->summary() << ", combined beyond the parity test's judgement (its wait ran out) "
      << combined_unjudged_;
  return s.str();
}

}  // namespace navbus::nav_filter
