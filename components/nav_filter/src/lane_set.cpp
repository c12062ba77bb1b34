#include "navbus/nav_filter/lane_set.hpp"

#include <algorithm>
#include <sstream>

#include <spdlog/spdlog.h>
#include <Eigen/Geometry>

#include "navbus/core/math/earth.hpp"

namespace navbus::nav_filter {

namespace {

/// The configuration of the lane of `unit`: its IMU, its mounting, the antenna seen from it.
/// Lanes after the first neither answer the fault monitor nor run the low-latency output.
FilterConfig laneConfig(const FilterConfig& base, const LaneUnit& unit, bool first) {
  FilterConfig c = base;
  c.lanes = {};
  c.imu.id = unit.sensor_id;
  c.imu_mounting.sensor_to_body = unit.c_b_u;
  c.engine.antenna_lever_arm_b_m = base.engine.antenna_lever_arm_b_m - unit.lever_arm_b_m;
  if (!first) {
    c.fault_monitor.reset();
    c.low_latency_output = false;
  }
  return c;
}

bool isImuCommand(const navbus::FilterCommand& c) {
  switch (c.kind()) {
    case navbus::CMD_FAIL_SENSOR_AXIS:
    case navbus::CMD_RESTORE_SENSOR_AXIS:
    case navbus::CMD_COMPENSATE_BIAS:
    case navbus::CMD_RELEARN_BIAS:
      return true;
    case navbus::CMD_EXCLUDE_STREAM:
    case navbus::CMD_READMIT_STREAM:
      return c.sensor() == navbus::SOURCE_IMU_STREAM;
    default:
      return false;
  }
}

core::NavState navState(const navbus::NavigationSolution& s) {
  core::NavState n;
  n.time_ns = static_cast<std::int64_t>(s.time_gps_ns());
  n.position = {s.latitude_rad(), s.longitude_rad(), s.height_m()};
  n.vel_ned_mps = {s.vel_ned_mps()[0], s.vel_ned_mps()[1], s.vel_ned_mps()[2]};
  n.q_b_to_n =
      Eigen::Quaterniond(s.q_b_to_n()[0], s.q_b_to_n()[1], s.q_b_to_n()[2], s.q_b_to_n()[3]);
  return n;
}

/// The lane's solution (its IMU's place) moved to the body origin, r_b from it.
navbus::NavigationSolution atBodyOrigin(navbus::NavigationSolution s, const Eigen::Vector3d& r_b) {
  if (r_b.isZero()) return s;
  const core::NavState n = navState(s);
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
    : config_(config), sinks_(std::move(sinks)), selector_(config.lanes.selector) {
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
    lanes_.push_back(std::make_unique<FilterPipeline>(laneConfig(config_, units[k], first), h, s));
  }
  pending_.resize(units.size());
  excluded_.assign(units.size(), false);
  ended_.assign(units.size(), false);
  statuses_.resize(units.size());
}

int LaneSet::laneOf(std::uint32_t sensor_id) const {
  const auto& units = config_.lanes.units;
  for (std::size_t k = 0; k < units.size(); ++k)
    if (units[k].sensor_id == sensor_id) return static_cast<int>(k);
  return -1;
}

void LaneSet::onImu(const navbus::ImuIncrement& msg) {
  // Another IMU's increment goes to lane 0, which refuses it as an unexpected source (counted).
  const int k = std::max(laneOf(msg.sensor_id()), 0);
  lanes_[static_cast<std::size_t>(k)]->onImu(msg);
}

void LaneSet::onImuBlock(const navbus::ImuIncrementBlock& msg) {
  const int k = std::max(laneOf(msg.sensor_id()), 0);
  lanes_[static_cast<std::size_t>(k)]->onImuBlock(msg);
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

void LaneSet::onStreamEnded(bus::StreamKind kind, std::uint32_t id) {
  if (kind != bus::StreamKind::kImu || lanes_.size() == 1) {
    forEach([&](FilterPipeline& l) { l.onStreamEnded(kind, id); });
    return;
  }
  const int k = laneOf(id);
  if (k < 0) return lanes_.front()->onStreamEnded(kind, id);  // logged there as not in use
  ended_[static_cast<std::size_t>(k)] = true;                 // no longer waited for
  lanes_[static_cast<std::size_t>(k)]->onStreamEnded(kind, id);
  release(false);
}

void LaneSet::onCommand(const navbus::FilterCommand& c,
                        const std::optional<std::string>& writer_identity) {
  if (lanes_.size() == 1) return lanes_.front()->onCommand(c, writer_identity);
  if (!isImuCommand(c)) {
    forEach([&](FilterPipeline& l) { l.onCommand(c, writer_identity); });
    release(false);
    return;
  }
  // An IMU's command concerns its lane (sensor_id 0: the filter's own IMU, lane 0's); one for
  // an IMU without a lane goes to lane 0, which refuses it naming the id.
  const int named = laneOf(c.sensor_id() == 0 ? config_.imu.id : c.sensor_id());
  const auto k = static_cast<std::size_t>(std::max(named, 0));
  if (named > 0) routed_.insert({c.issuer().to_string(), c.run_id(), c.command_id()});
  if (named >= 0) {
    const bool out =
        c.kind() == navbus::CMD_FAIL_SENSOR_AXIS || c.kind() == navbus::CMD_EXCLUDE_STREAM;
    const bool back =
        c.kind() == navbus::CMD_RESTORE_SENSOR_AXIS || c.kind() == navbus::CMD_READMIT_STREAM;
    if (out || back) excluded_[k] = out;
  }
  lanes_[k]->onCommand(c, writer_identity);
  release(false);
}

void LaneSet::pump(std::int64_t now_ns) {
  forEach([&](FilterPipeline& l) { l.pump(now_ns); });
}

void LaneSet::resumedAfterStall(std::int64_t now_ns, std::int64_t stalled_ns) {
  forEach([&](FilterPipeline& l) { l.resumedAfterStall(now_ns, stalled_ns); });
}

void LaneSet::setWritersAlive(bus::StreamKind kind, bool alive, std::int64_t now_ns) {
  forEach([&](FilterPipeline& l) { l.setWritersAlive(kind, alive, now_ns); });
}

void LaneSet::flush(std::int64_t now_ns) {
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
  // The lane's fit as it stands at this solution (the engine moves on before the selection).
  pending_[i].push_back({atBodyOrigin(s, config_.lanes.units[i].lever_arm_b_m),
                         lanes_[i]->engine().consistency().windowNisPerRow()});
  release(false);
}

void LaneSet::release(bool all) {
  for (;;) {
    std::int64_t t = -1;
    std::size_t deepest = 0;
    bool waiting = false;
    for (std::size_t k = 0; k < pending_.size(); ++k) {
      deepest = std::max(deepest, pending_[k].size());
      if (pending_[k].empty()) {
        waiting = waiting || !(excluded_[k] || ended_[k]);
        continue;
      }
      const auto front = static_cast<std::int64_t>(pending_[k].front().solution.time_gps_ns());
      if (t < 0 || front < t) t = front;
    }
    if (t < 0) return;
    if (waiting && !all) {
      if (deepest <= config_.lanes.max_pending) return;
      ++passed_over_;  // the slow lane is unavailable at this time
    }
    select(t);
  }
}

bool LaneSet::available(int k, const Pending* p) const {
  if (!p || excluded_[static_cast<std::size_t>(k)]) return false;
  const navbus::NavigationSolution& s = p->solution;
  return s.covariance_valid() && s.mode() != navbus::MODE_ALIGNING &&
         s.mode() != navbus::MODE_INERTIAL_LOST;
}

void LaneSet::select(std::int64_t time_ns) {
  std::vector<const Pending*> at(pending_.size(), nullptr);
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    if (!pending_[k].empty() &&
        static_cast<std::int64_t>(pending_[k].front().solution.time_gps_ns()) == time_ns)
      at[k] = &pending_[k].front();
    core::LaneStatus& st = statuses_[k];
    st.available = available(static_cast<int>(k), at[k]);
    st.test_ratio = at[k] ? at[k]->test_ratio : 0.0;
    if (at[k]) st.solution = navState(at[k]->solution);
  }
  const core::LaneSelection& sel = selector_.update(statuses_);
  if (sel.switched) {
    last_delta_ = sel.delta;
    spdlog::warn(
        "lanes: switched from IMU {} to IMU {} at {:.3f} s ({}), reset {}: position "
        "{:.3f} m, velocity {:.4f} m/s, attitude {:.3g} mrad",
        config_.lanes.units[static_cast<std::size_t>(sel.previous_lane)].sensor_id,
        config_.lanes.units[static_cast<std::size_t>(sel.lane)].sensor_id,
        1e-9 * static_cast<double>(time_ns),
        sel.reason == core::LaneSwitchReason::kUnavailable ? "the lane became unavailable"
                                                           : "a clearly better fit",
        sel.reset_count, sel.delta.position_ned_m.norm(), sel.delta.velocity_ned_mps.norm(),
        1e3 * sel.delta.attitude_ned_rad.norm());
  }
  // Every lane's solution on its own instance; the selected one published.
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    if (!at[k]) continue;
    if (sinks_.lane) {
      navbus::LaneSolution l;
      l.vehicle_id(config_.vehicle_id);
      l.lane_id(config_.lanes.units[k].sensor_id);
      l.selected(static_cast<int>(k) == sel.lane);
      l.available(statuses_[k].available);
      l.test_ratio(at[k]->test_ratio);
      l.solution(at[k]->solution);
      sinks_.lane(l);
    }
  }
  if (sel.lane >= 0 && at[static_cast<std::size_t>(sel.lane)]) {
    navbus::NavigationSolution out = at[static_cast<std::size_t>(sel.lane)]->solution;
    out.seq(++seq_);
    out.reset_count(sel.reset_count);
    setDelta(out, last_delta_);
    sinks_.filter.solution(out);
  }
  for (std::size_t k = 0; k < pending_.size(); ++k)
    if (at[k]) pending_[k].pop_front();
}

std::string LaneSet::summary() const {
  if (lanes_.size() == 1) return lanes_.front()->summary();
  std::ostringstream s;
  const core::LaneSelection& sel = selector_.last();
  s << "lanes: " << lanes_.size() << ", selected IMU "
    << (sel.lane >= 0 ? config_.lanes.units[static_cast<std::size_t>(sel.lane)].sensor_id : 0)
    << ", switches " << sel.reset_count << ", solutions published " << seq_
    << ", lane solutions passed over (a lane " << config_.lanes.max_pending << " solutions behind) "
    << passed_over_;
  for (std::size_t k = 0; k < lanes_.size(); ++k)
    s << (k == 0 ? "; " : "\n") << "lane IMU " << config_.lanes.units[k].sensor_id
      << (excluded_[k] ? " (excluded)" : "") << ": " << lanes_[k]->summary();
  return s.str();
}

}  // namespace navbus::nav_filter
