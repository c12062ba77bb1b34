// constexpr layout of the error-state vectors, so that code names blocks instead of indices
// (`P.block<3, 3>(kVel.index, kVel.index)`, never `P(4, 4)`).
#pragma once

#include <bitset>

namespace navbus::core {

struct StateBlock {
  int index;  ///< first element in the state vector
  int dof;    ///< number of elements
  constexpr int end() const { return index + dof; }
};

/// The error state of every filter (seed 000 eqs. 1 and 3, seed 001 eq. 17), in NED:
/// position error [m, N E D], velocity error [m/s, NED], attitude error phi [rad, NED; the
/// computed body-to-NED rotation is (I - [phi x]) times the true one], accelerometer bias
/// [m/s^2, body], gyro bias [rad/s, body], star-tracker bias [rad, star-tracker body axes: a
/// small rotation of the measured attitude, first-order Gauss-Markov], the accelerometer and
/// gyro scale-factor errors [1, body; a sensor reads (1 + s) times the truth plus its bias, per
/// axis], receiver clock bias c*b [m] and drift c*f [m/s], and the time-correlated pseudorange
/// errors of up to kPseudorangeError.dof satellites [m, one first-order Gauss-Markov state per
/// tracked satellite, assigned by pseudorange_error_slots.hpp]. All errors are estimate minus
/// truth. Seed
/// 000 orders dV, dR, Psi,
/// ...; the order here is position first, which only permutes the matrices. A configuration
/// uses the blocks it has sensors for (the others are inactive, error_state.hpp): the 17
/// states of seed 000 without the star-tracker bias, seed 001 without the clock.
namespace layout {
inline constexpr StateBlock kPos{0, 3};
inline constexpr StateBlock kVel{3, 3};
inline constexpr StateBlock kAtt{6, 3};
inline constexpr StateBlock kAccelBias{9, 3};
inline constexpr StateBlock kGyroBias{12, 3};
inline constexpr StateBlock kStarTrackerBias{15, 3};
inline constexpr StateBlock kAccelScale{18, 3};
inline constexpr StateBlock kGyroScale{21, 3};
inline constexpr StateBlock kClockBias{24, 1};
inline constexpr StateBlock kClockDrift{25, 1};
inline constexpr StateBlock kPseudorangeError{26, 12};
inline constexpr int kSize = 38;
/// A filter fusing two GNSS receivers: the second receiver's clock bias c*b [m] and drift c*f
/// [m/s] (its own oscillator; the first's are kClockBias and kClockDrift) take the last two
/// states of the pseudorange-error block, whose time-correlated errors such a filter models for
/// at most kPseudorangeError.dof - 2 satellites (pseudorange_error_slots.hpp). Shared rather than
/// appended: two more states cost every filter, one receiver or two, 14-21 % of its IMU cycle
/// (measured: docs/results.md), for what only the second receiver's filter uses.
inline constexpr StateBlock kSecondClockBias{kPseudorangeError.end() - 2, 1};
inline constexpr StateBlock kSecondClockDrift{kPseudorangeError.end() - 1, 1};
/// Receivers whose pseudoranges one filter fuses, each with its own clock states.
inline constexpr int kMaxFusedReceivers = 2;
/// The clock bias and drift states of fused receiver `index` (0: the first).
constexpr StateBlock clockBiasOf(int index) {
  return index == 0 ? kClockBias : kSecondClockBias;
}
constexpr StateBlock clockDriftOf(int index) {
  return index == 0 ? kClockDrift : kSecondClockDrift;
}
/// Loose coupling has no pseudoranges: there the first three states of the receiver's error
/// block are the GNSS fix's position error [m, NED, first-order Gauss-Markov; estimate minus
/// truth]. The aiding mode says which meaning the block has; the two are never active together
/// (the configuration refuses each error model outside its mode).
inline constexpr StateBlock kFixPositionError{kPseudorangeError.index, 3};
/// A land vehicle has no star tracker: there the star tracker's block holds the residual
/// mounting misalignment between the body axes the IMU is rotated into and the vehicle's own
/// [rad, body axes: the vehicle's axes are (I - [mu x]) times the body's; random constants,
/// estimate minus truth], which the non-holonomic constraint needs. The multi-dimensional
/// filter (the only one with that constraint) takes no star-tracker updates, so the two are
/// never active together.
inline constexpr StateBlock kMountingMisalignment{kStarTrackerBias.index, 3};
/// The leading states the error dynamics couple (position, velocity, attitude). No navigation
/// error drives the trailing ones (biases, clock, pseudorange errors, scale factors), so every
/// transition matrix is block upper triangular at this size (ins_error_model.hpp, tested).
inline constexpr int kCoupledSize = kAtt.end();
static_assert(kPos.end() == kVel.index && kVel.end() == kAtt.index &&
                  kAtt.end() == kAccelBias.index && kAccelBias.end() == kGyroBias.index &&
                  kGyroBias.end() == kStarTrackerBias.index &&
                  kStarTrackerBias.end() == kAccelScale.index &&
                  kAccelScale.end() == kGyroScale.index && kGyroScale.end() == kClockBias.index &&
                  kClockBias.end() == kClockDrift.index &&
                  kClockDrift.end() == kPseudorangeError.index && kPseudorangeError.end() == kSize,
              "the layout's blocks must tile the state vector");
static_assert(kFixPositionError.end() <= kPseudorangeError.end(),
              "the fix's position error shares the receiver's error block");
static_assert(kSecondClockBias.end() == kSecondClockDrift.index &&
                  kSecondClockDrift.end() == kPseudorangeError.end() &&
                  kSecondClockBias.index >= kFixPositionError.end(),
              "a second receiver's clock shares the pseudorange-error block's last states");
}  // namespace layout

/// Which states of the layout a filter estimates (the others are inactive, error_state.hpp).
using StateMask = std::bitset<layout::kSize>;

}  // namespace navbus::core
