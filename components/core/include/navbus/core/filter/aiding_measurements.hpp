// Loosely coupled aiding measurements over the state layout: GNSS position and velocity
// (seed 004 eq. 5, seed 001) and star-tracker attitude (seed 001 eq. 17). Each returns the
// innovation z = predicted - measured in error-state form (z = H dx + v), H and R.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "navbus/core/ins/state_layout.hpp"
#include "navbus/core/ins/strapdown.hpp"

namespace navbus::core {

/// An M-row aiding measurement in error-state form.
template <int M>
struct AidingMeasurement {
  static constexpr int kRows = M;
  Eigen::Matrix<double, M, 1> z;              ///< innovation, predicted minus measured
  Eigen::Matrix<double, M, layout::kSize> h;  ///< d z / d dx
  Eigen::Matrix<double, M, M> r;              ///< measurement noise covariance
};
using VectorMeasurement = AidingMeasurement<3>;

/// GNSS position fix of the antenna, at `lever_arm_b_m` from the IMU in body axes: z = (INS
/// position + C_b_n l_b - fix position) in NED metres. With C_b_n,est = (I - [phi x]) C_b_n the
/// antenna term's error is -phi x (C_b_n l) = [(C_b_n l) x] phi: H is I on the position error
/// and [(C_b_n l) x] on the attitude error.
/// With `fix_error_ned_m` (the estimated fix position error b^, layout::kFixPositionError) the
/// predicted fix includes it: z gains b^ and H has I on those states (the fix is the antenna
/// plus its error b; z = dp + (b^ - b) - v).
VectorMeasurement positionMeasurement(
    const NavState& ins, const earth::Geodetic& fix, const Eigen::Vector3d& sigma_ned_m,
    const Eigen::Vector3d& lever_arm_b_m = Eigen::Vector3d::Zero(),
    const Eigen::Vector3d* fix_error_ned_m = nullptr);

/// GNSS velocity of the antenna: z = INS velocity + C_b_n (w_nb_b x l_b) - fix velocity [m/s,
/// NED], w_nb_b the body's angular rate relative to NED (the gyro rate less the Earth and
/// transport rates, which change the antenna term by under 1e-4 of it: neglected). H is I on
/// the velocity error and [(C_b_n (w x l)) x] on the attitude error; the gyro-bias error's
/// term (l x db, under 1e-4 m/s for a decimetre arm and 0.1 deg/s) is left out.
VectorMeasurement velocityMeasurement(
    const NavState& ins, const Eigen::Vector3d& fix_vel_ned_mps,
    const Eigen::Vector3d& sigma_ned_mps,
    const Eigen::Vector3d& lever_arm_b_m = Eigen::Vector3d::Zero(),
    const Eigen::Vector3d& rate_nb_b_radps = Eigen::Vector3d::Zero());

/// Star tracker: the measured body-to-ECI attitude brought into NED at the INS position and
/// time; z = phi_INS - phi_ST (seed 001 eq. 17) as the small rotation between the INS attitude
/// and the measured one. Body-axis sigmas are rotated into NED. The tracker's bias b (a small
/// rotation about its axes, which are the body axes: C_meas = C_true exp([b + v] x)) appears
/// in NED as C_b_n b: with the estimate b^ subtracted, z = phi - C_b_n (b^ - b) + C_b_n v, so
/// H selects phi and gives -C_b_n on the bias error states.
VectorMeasurement attitudeMeasurement(const NavState& ins,
                                      const Eigen::Quaterniond& q_b_to_i_measured,
                                      const Eigen::Vector3d& sigma_b_rad,
                                      const Eigen::Vector3d& bias_estimate_b_rad);

/// Zero-velocity update while the vehicle stands still (seed 004 eq. 4): z = V_INS - 0 [m/s,
/// NED], H selects the velocity error.
VectorMeasurement zeroVelocityMeasurement(const NavState& ins, double sigma_mps);

/// Non-holonomic constraint of a land vehicle (seed 004 eq. 6): the lateral and vertical body
/// velocities are zero, z = (C_n_b V_INS)_{y,z} [m/s, body]. With C_b_n,est = (I - [phi x])
/// C_b_n, the body velocity error is C_n_b dV - C_n_b [V x] phi, which gives the velocity and
/// attitude columns of H. With `velocity_pitch_b_rad` the vertical row expects the velocity
/// that far above the forward axis (the body pitched against the track, as a car's under
/// acceleration): z_D = v_b,z + v_b,x tan(velocity_pitch_b_rad), H's vertical row gaining
/// tan() times the forward row.
///
/// With `mounting_rad` (the estimated residual mounting misalignment mu, nullptr: not
/// modelled) the constraint holds in the vehicle's axes, v_v = (I - [mu x]) v_b; the error of
/// v_v gains [v_b x] d(mu) (estimate minus truth), the columns of layout::kMountingMisalignment,
/// and the velocity and attitude columns turn by (I - [mu x]).
AidingMeasurement<2> nonHolonomicMeasurement(const NavState& ins, double sigma_mps,
                                             double velocity_pitch_b_rad = 0.0,
                                             const Eigen::Vector3d* mounting_rad = nullptr);

}  // namespace navbus::core
