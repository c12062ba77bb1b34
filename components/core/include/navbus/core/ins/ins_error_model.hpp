// Continuous-time error dynamics of the strapdown INS and the receiver clock over the state
// layout of state_layout.hpp (phi-angle attitude error, NED position error in metres of the
// curvilinear position), and the transition matrix of one propagation step. The model is the
// full local-level one (Titterton & Weston, Strapdown Inertial Navigation Technology, ch. 12;
// Shin, EKF-based adaptive INS/GNSS, 2005, ch. 2): the Earth and transport rates' dependence on
// the position and velocity errors is kept, which matters in orbit (seed 001, 7.6 km/s).
#pragma once

#include <Eigen/Core>

#include "navbus/core/ins/state_layout.hpp"
#include "navbus/core/ins/strapdown.hpp"
#include "navbus/core/math/sparse_rows.hpp"

namespace navbus::core {

using StateMatrix = Eigen::Matrix<double, layout::kSize, layout::kSize>;

/// F of dx/dt = F dx at `state`, with the compensated specific force `f_b` and angular rate
/// `w_ib_b` in the body frame:
///   d(dr)/dt  = -[w_en x] dr + dv
///   d(dv)/dt  = [f_n x] phi - (2 w_ie + w_en) x dv - C_b_n (dba + diag(f_b) dsa)
///               + (2 g / R) dr_D e_D
///   d(phi)/dt = -w_in x phi + d(w_en)/d(dv) dv + C_b_n (dbg + diag(w_ib_b) dsg)
///   d(cb)/dt  = cd,  d(cd)/dt = 0           (seed 000 eq. 3)
/// Errors are estimate minus truth; biases and scale factors (dsa, dsg: a sensor that reads
/// (1 + s) times the truth plus the bias, compensated as (reading - b) / (1 + s)) are random
/// constants (seed 000 eq. 1). The small couplings of position error into the Earth and
/// transport rates are neglected.
StateMatrix errorDynamics(const NavState& state, const Eigen::Vector3d& f_b,
                          const Eigen::Vector3d& w_ib_b, earth::GravityModel gravity);
/// The same with the Earth at the state already computed (earth::localEarth).
StateMatrix errorDynamics(const NavState& state, const Eigen::Vector3d& f_b,
                          const Eigen::Vector3d& w_ib_b, const earth::LocalEarth& at_state);

/// The 3 x 3 blocks of F that vary with the state and the IMU's readings, and the weight of its
/// constant couplings (dr/dv = I, the clock bias's drift = 1). F is linear in them, so the
/// blocks of several increments summed with their intervals as weights (addScaled) are the
/// blocks of the integral of F over those increments, constant couplings times the time.
struct ErrorDynamicsBlocks {
  Eigen::Matrix3d pos_pos, vel_pos, vel_vel, vel_att, vel_accel_bias, vel_accel_scale;
  Eigen::Matrix3d att_pos, att_vel, att_att, att_gyro_bias, att_gyro_scale;
  double constant{1.0};  ///< 1 in F; the time in an integral of F

  ErrorDynamicsBlocks& operator*=(double s);
  /// += s b.
  void addScaled(const ErrorDynamicsBlocks& b, double s);
};

/// F's blocks at `state` (the arguments of errorDynamics()).
ErrorDynamicsBlocks errorDynamicsBlocks(const NavState& state, const Eigen::Vector3d& f_b,
                                        const Eigen::Vector3d& w_ib_b,
                                        const earth::LocalEarth& at_state);
/// The matrix of the blocks (F, or its integral when they are one).
StateMatrix errorDynamics(const ErrorDynamicsBlocks& blocks);

/// Transition matrix over dt: I + F dt + (F dt)^2 / 2.
StateMatrix transitionMatrix(const StateMatrix& F, double dt);

/// The elements errorDynamics() can fill (read once from a state where all of them are
/// nonzero), and those of a transitionMatrix() built from such an F (I + F + F^2). Every
/// transition matrix of the filters lies within the latter (tested at random states).
const SparsityPattern<layout::kSize>& errorDynamicsPattern();
const SparsityPattern<layout::kSize>& transitionPattern();

}  // namespace navbus::core
