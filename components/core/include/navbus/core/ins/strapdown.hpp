// Strapdown inertial mechanization in the local NED frame on WGS84, driven by increments.
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navbus/core/math/earth.hpp"

namespace navbus::core {

/// One navigation-rate IMU output in SI units (the core's view of an increment).
struct ImuIncrement {
  std::int64_t time_ns{0};                                     ///< end of the interval, GPS time
  double interval_s{0.0};                                      ///< interval length
  Eigen::Vector3d delta_vel_b_mps{Eigen::Vector3d::Zero()};    ///< specific-force integral, body
  Eigen::Vector3d delta_angle_b_rad{Eigen::Vector3d::Zero()};  ///< inertial-rate integral, body
};

/// Position, velocity and attitude of the body.
struct NavState {
  std::int64_t time_ns{0};                                      ///< GPS time of validity
  earth::Geodetic position;                                     ///< WGS84
  Eigen::Vector3d vel_ned_mps{Eigen::Vector3d::Zero()};         ///< w.r.t. Earth, NED
  Eigen::Quaterniond q_b_to_n{Eigen::Quaterniond::Identity()};  ///< body -> NED
};

/// Strapdown mechanization with two-sample coning and sculling corrections
/// (Savage, Strapdown Analytics, ch. 7; increments from the previous interval are kept).
/// The navigation-frame rotation, gravity and Coriolis terms are evaluated at the mid-interval
/// state extrapolated from the previous step, which keeps the algorithm second-order accurate.
class StrapdownNed {
 public:
  explicit StrapdownNed(earth::GravityModel gravity = earth::GravityModel::kWgs84Normal)
      : gravity_(gravity) {}

  /// Starts from a known state; the first increment after this has no coning partner.
  void initialize(const NavState& state);

  /// Integrates one increment whose interval ends at inc.time_ns and starts at state time.
  void propagate(const ImuIncrement& inc) { propagate(inc, earthAtState()); }
  /// The same, with the Earth at the state (earthAtState()) already computed for the error
  /// model of the same step.
  void propagate(const ImuIncrement& inc, const earth::LocalEarth& at_state);
  /// The Earth rates, radii and gravity at the current position and velocity.
  earth::LocalEarth earthAtState() const {
    return earth::localEarth(gravity_, state_.position, state_.vel_ned_mps);
  }

  /// Restarts the integration at a new time without propagating across a gap
  /// (the vehicle state cannot be known across missing inertial data).
  void restartAt(std::int64_t time_ns);

  /// Replaces position, velocity and attitude by corrected values (filter feedback), keeping
  /// the time and the previous increment used by the coning and sculling corrections.
  void correct(const NavState& corrected) {
    const std::int64_t t = state_.time_ns;
    state_ = corrected;
    state_.time_ns = t;
  }

  const NavState& state() const { return state_; }
  bool initialized() const { return initialized_; }

 private:
  earth::GravityModel gravity_;
  NavState state_;
  ImuIncrement previous_;
  bool has_previous_{false};
  bool initialized_{false};
};

}  // namespace navbus::core
