// Which of several filter lanes (one filter per IMU of a redundant installation) the published
// solution follows, after PX4's EKF2 selector and ArduPilot's EKF3 lanes: the lane with the
// smallest innovation test ratio, kept until another has been clearly better (its ratio at most
// `switch_ratio` times the selected lane's) for `confirm_epochs` epochs in a row; a lane that is
// no longer available (its IMU excluded by a fault decision, or not aligned) is left at once for
// the best available one. A switch makes the published solution jump from one lane's estimate to
// another's: the selection reports the jump (position, velocity and attitude deltas, new minus
// old, at the switch) and counts the switches, so that a consumer can carry its own states over
// the jump (PX4's reset deltas and counters).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

struct LaneSelectorConfig {
  /// A candidate must have a test ratio at most this fraction of the selected lane's ...
  double switch_ratio{0.5};
  /// ... for this many consecutive epochs before the selector switches to it.
  int confirm_epochs{5};
  /// A lane taken first, and whenever the selected lane is left as unavailable, while it is
  /// available itself (the least-squares lane of all instruments); -1: none.
  int preferred{-1};
};

/// One lane at one epoch, as the selector sees it.
struct LaneStatus {
  bool available{true};
  /// The lane's innovation test ratio: its normalised innovations squared over their
  /// threshold (1 = at the gate); smaller fits better; 0: no fit yet (a lane without one is
  /// never a better fit, and is taken only when no available lane has one).
  double test_ratio{0.0};
  NavState solution;  ///< the lane's estimate at this epoch
};

/// The jump of the published solution at a switch: new lane minus old lane.
struct LaneResetDelta {
  Eigen::Vector3d position_ned_m{Eigen::Vector3d::Zero()};  ///< at the old lane's position
  Eigen::Vector3d velocity_ned_mps{Eigen::Vector3d::Zero()};
  /// Rotation vector of q_new q_old^-1 [rad, NED]: the attitude turned by it is the new one.
  Eigen::Vector3d attitude_ned_rad{Eigen::Vector3d::Zero()};
};

enum class LaneSwitchReason { kNone, kFirst, kUnavailable, kBetterFit };

struct LaneSelection {
  int lane{-1};  ///< -1 while no lane is available
  bool switched{false};
  LaneSwitchReason reason{LaneSwitchReason::kNone};
  int previous_lane{-1};
  LaneResetDelta delta;          ///< of this epoch's switch (zero without one)
  std::uint32_t reset_count{0};  ///< switches so far (a consumer sees each jump once)
};

class LaneSelector {
 public:
  explicit LaneSelector(const LaneSelectorConfig& config = {}) : config_(config) {}

  /// One epoch of every lane, in lane order (the same number of lanes every epoch).
  const LaneSelection& update(const std::vector<LaneStatus>& lanes);
  const LaneSelection& last() const { return selection_; }

 private:
  int bestAvailable(const std::vector<LaneStatus>& lanes) const;
  /// The preferred lane when it is available, else `best`.
  int preferredOr(int best, const std::vector<LaneStatus>& lanes) const;
  void switchTo(int lane, LaneSwitchReason reason, const std::vector<LaneStatus>& lanes);

  LaneSelectorConfig config_;
  LaneSelection selection_;
  int candidate_{-1};  ///< the lane that has been better, and for how many epochs
  int candidate_epochs_{0};
};

/// The deltas new - old between two lanes' solutions (LaneResetDelta).
LaneResetDelta laneResetDelta(const NavState& from, const NavState& to);

}  // namespace navbus::core
