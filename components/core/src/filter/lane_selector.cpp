#include "navbus/core/filter/lane_selector.hpp"

#include <Eigen/Geometry>

#include "navbus/core/math/earth.hpp"

namespace navbus::core {

LaneResetDelta laneResetDelta(const NavState& from, const NavState& to) {
  LaneResetDelta d;
  d.position_ned_m = earth::differenceNed(to.position, from.position);
  d.velocity_ned_mps = to.vel_ned_mps - from.vel_ned_mps;
  // Eigen's angle-axis of a quaternion is the shorter way round (an angle in [0, pi]).
  const Eigen::AngleAxisd turn(to.q_b_to_n * from.q_b_to_n.conjugate());
  d.attitude_ned_rad = turn.angle() * turn.axis();
  return d;
}

int LaneSelector::bestAvailable(const std::vector<LaneStatus>& lanes) const {
  // A lane without a fit yet (its window restarted, e.g. after a re-initialisation: ratio 0)
  // has shown nothing: it is taken only when no available lane has a fit.
  int best = -1;
  auto fits = [](const LaneStatus& l) { return l.test_ratio > 0.0; };
  for (int i = 0; i < static_cast<int>(lanes.size()); ++i) {
    const LaneStatus& l = lanes[static_cast<std::size_t>(i)];
    if (!l.available) continue;
    if (best < 0) {
      best = i;
      continue;
    }
    const LaneStatus& b = lanes[static_cast<std::size_t>(best)];
    if ((fits(l) && !fits(b)) || (fits(l) == fits(b) && l.test_ratio < b.test_ratio)) best = i;
  }
  return best;
}

int LaneSelector::preferredOr(int best, const std::vector<LaneStatus>& lanes) const {
  const int p = config_.preferred;
  return p >= 0 && p < static_cast<int>(lanes.size()) &&
                 lanes[static_cast<std::size_t>(p)].available
             ? p
             : best;
}

void LaneSelector::switchTo(int lane, LaneSwitchReason reason,
                            const std::vector<LaneStatus>& lanes) {
  const int from = selection_.lane;
  selection_.previous_lane = from;
  selection_.lane = lane;
  selection_.reason = reason;
  candidate_ = -1;
  candidate_epochs_ = 0;
  if (from < 0 || lane < 0) return;  // nothing was published before, or nothing is now
  selection_.switched = true;
  selection_.delta = laneResetDelta(lanes[static_cast<std::size_t>(from)].solution,
                                    lanes[static_cast<std::size_t>(lane)].solution);
  ++selection_.reset_count;
}

const LaneSelection& LaneSelector::update(const std::vector<LaneStatus>& lanes) {
  selection_.switched = false;
  selection_.reason = LaneSwitchReason::kNone;
  selection_.delta = LaneResetDelta{};
  const int current = selection_.lane;
  const int best = bestAvailable(lanes);
  if (current < 0 || current >= static_cast<int>(lanes.size())) {
    if (best >= 0) switchTo(preferredOr(best, lanes), LaneSwitchReason::kFirst, lanes);
    return selection_;
  }
  if (!lanes[static_cast<std::size_t>(current)].available) {
    switchTo(preferredOr(best, lanes), LaneSwitchReason::kUnavailable, lanes);
    return selection_;
  }
  // Hysteresis: the best lane must beat the selected one clearly, epoch after epoch.
  const double ratio = lanes[static_cast<std::size_t>(current)].test_ratio;
  const double best_ratio = lanes[static_cast<std::size_t>(best)].test_ratio;
  const bool better =
      best != current && best_ratio > 0.0 && best_ratio <= config_.switch_ratio * ratio;
  if (!better) {
    candidate_ = -1;
    candidate_epochs_ = 0;
    return selection_;
  }
  candidate_epochs_ = best == candidate_ ? candidate_epochs_ + 1 : 1;
  candidate_ = best;
  if (candidate_epochs_ >= config_.confirm_epochs)
    switchTo(best, LaneSwitchReason::kBetterFit, lanes);
  return selection_;
}

}  // namespace navbus::core
