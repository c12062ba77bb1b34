// Truth trajectories on WGS84 with Earth rotation, and the perfect inertial increments along
// them: the integrals of the body's inertial angular rate and specific force, which a perfect
// IMU outputs, so that integrating them reproduces the trajectory.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/units.hpp"

namespace navbus::sim {

/// Perfect increments over one (sub-)interval.
struct PerfectIncrement {
  Eigen::Vector3d delta_angle_b_rad{Eigen::Vector3d::Zero()};
  Eigen::Vector3d delta_vel_b_mps{Eigen::Vector3d::Zero()};
};

class Trajectory {
 public:
  virtual ~Trajectory() = default;
  /// Truth position, velocity and attitude now (time_ns is set by the caller's clock).
  virtual core::NavState state() const = 0;
  /// Specific force in the body frame now (for g-dependent sensor errors).
  virtual Eigen::Vector3d specificForceBody() const = 0;
  /// Advances by dt and returns the perfect increments over the step.
  virtual PerfectIncrement advance(double dt_s) = 0;
  /// Seconds since the start.
  virtual double elapsed() const = 0;
};

/// One piece of a vehicle trajectory with constant commands. Rates are in SI.
struct Segment {
  double duration_s{0.0};
  double accel_mps2{0.0};          ///< along the velocity
  double heading_rate_radps{0.0};  ///< of the velocity vector (track)
  double climb_rate_radps{0.0};    ///< of the flight-path angle
  double roll_rate_radps{0.0};     ///< Euler angle rates of the body attitude (3-2-1)
  double pitch_rate_radps{0.0};
  double yaw_rate_radps{0.0};
};

struct VehicleStart {
  core::earth::Geodetic position{36.5 * units::kDeg, 127.5 * units::kDeg, 100.0};  ///< seed 000
  double speed_mps{0.0};
  double heading_rad{0.0};      ///< velocity track angle from north
  double flight_path_rad{0.0};  ///< velocity elevation
  Eigen::Vector3d roll_pitch_yaw_rad{Eigen::Vector3d::Zero()};
};

/// An aircraft or land vehicle driven by segments (stationary, acceleration, constant
/// velocity, turns, attitude manoeuvres). The kinematic state (position, speed, velocity
/// direction, Euler angles) and the two increment integrals are integrated together by RK4,
/// with steps split at segment boundaries. After the last segment the vehicle keeps its state
/// with zero commands.
class VehicleTrajectory : public Trajectory {
 public:
  VehicleTrajectory(const VehicleStart& start, std::vector<Segment> segments,
                    core::earth::GravityModel gravity, double max_step_s = 0.0025);
  core::NavState state() const override;
  Eigen::Vector3d specificForceBody() const override;
  PerfectIncrement advance(double dt_s) override;
  double elapsed() const override { return t_; }
  /// Total duration of the segments.
  double duration() const;

  using Vector = Eigen::Matrix<double, 15, 1>;

 private:
  const Segment& segmentAt(double t) const;
  double segmentEnd(double t) const;
  Vector derivative(const Vector& x, const Segment& c) const;
  void rk4(double h, const Segment& c);

  std::vector<Segment> segments_;
  core::earth::GravityModel gravity_;
  double max_step_s_;
  Vector x_;
  double t_{0.0};
  Segment idle_;
};

struct OrbitStart {
  double altitude_m{500e3};  ///< above a spherical Earth of radius a (WGS84 semi-major axis)
  double inclination_rad{34.0 * M_PI / 180};
  double latitude_rad{34.0 * M_PI / 180};  ///< start point (ascending pass, |lat| <= inclination)
  double longitude_rad{128.0 * M_PI / 180};
  double start_gps_s{0.0};  ///< GPS time of the start (fixes the Earth's orientation)
};

/// A circular Keplerian orbit around a point-mass Earth (seed 001), body axes in the local
/// vertical / local horizontal frame (x along track, z nadir). In free fall the specific force
/// is zero and the body turns at the orbital rate about its -y axis: the perfect increments
/// are exact closed forms.
class CircularOrbitTrajectory : public Trajectory {
 public:
  explicit CircularOrbitTrajectory(const OrbitStart& start);
  core::NavState state() const override;
  Eigen::Vector3d specificForceBody() const override { return Eigen::Vector3d::Zero(); }
  PerfectIncrement advance(double dt_s) override;
  double elapsed() const override { return t_; }
  double periodSeconds() const { return 2.0 * M_PI / n_; }
  /// Inertial (ECI of Common.idl) position and velocity now.
  Eigen::Vector3d positionEci() const;
  Eigen::Vector3d velocityEci() const;

 private:
  OrbitStart start_;
  double radius_m_;
  double n_;  ///< mean motion
  double raan_;
  /// Orbit plane to ECI: rotation about z by the right ascension of the ascending node, then
  /// about x by the inclination (constant; computed once).
  Eigen::Matrix3d C_orbit_i_;
  double u0_;  ///< argument of latitude at the start
  double t_{0.0};
};

}  // namespace navbus::sim
