// Propagation across an inertial gap (increments that never came: a lost stream, a sensor
// dropout). The engine holds the last increment's specific force and angular rate across the
// gap, in increments of its interval, and grows the covariance for the motion nobody
// measured: a change of specific force of `accel_sigma_mps2` (1-sigma, held for the whole gap)
// gives velocity (sigma_a T)^2 and position (sigma_a T^2 / 2)^2; a change of rate of
// `rate_sigma_radps` gives attitude (sigma_w T)^2 per axis. A gap longer than
// `max_bridged_s` is not propagated: the integration restarts where the data resume, the
// position variance grows by the distance the vehicle could have covered, (|v| T + sigma_a
// T^2 / 2)^2, and the engine re-initialises from the next GNSS solution, flagged
// (EngineMode::kReinitialising) until then. Either way the solution carries FAULT_IMU_GAP.
// Pure math.
#pragma once

#include <cstdint>
#include <vector>

#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

struct GapBridgeConfig {
  double max_bridged_s{30.0};    ///< longest gap propagated across [s]
  double accel_sigma_mps2{0.5};  ///< specific-force change while unmeasured, 1-sigma [m/s^2]
  double rate_sigma_radps{
      8.7e-3};  ///< angular-rate change while unmeasured, 1-sigma [rad/s] (0.5 deg/s)
};

/// Increments holding `last`'s specific force and rate from `from_ns` to `to_ns`, each of
/// `last`'s interval (the final one shorter).
std::vector<ImuIncrement> heldIncrements(const ImuIncrement& last, std::int64_t from_ns,
                                         std::int64_t to_ns);

/// What a gap of `gap_s` adds to each axis's variance.
struct GapVariances {
  double position_m2{0.0};
  double velocity_m2ps2{0.0};
  double attitude_rad2{0.0};
};
/// Bridged (propagated with held inputs) or not (restarted: the vehicle moved `speed_mps`
/// for the whole gap while the solution stood still).
GapVariances gapVariances(const GapBridgeConfig& c, double gap_s, bool bridged, double speed_mps);

}  // namespace navbus::core
