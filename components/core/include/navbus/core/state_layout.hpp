// constexpr layout of the error-state vectors, so that code names blocks instead of indices
// (`P.block<3, 3>(kVel.index, kVel.index)`, never `P(4, 4)`).
#pragma once

namespace navbus::core {

struct StateBlock {
  int index;  ///< first element in the state vector
  int dof;    ///< number of elements
  constexpr int end() const { return index + dof; }
};

/// The 17-state tightly coupled error state of seed 000 (eqs. 1 and 3), in NED:
/// position error [m, N E D], velocity error [m/s, NED], attitude error phi [rad, NED; the
/// computed body-to-NED rotation is (I - [phi x]) times the true one], accelerometer bias
/// [m/s^2, body], gyro bias [rad/s, body], receiver clock bias c*b [m] and drift c*f [m/s].
/// All errors are estimate minus truth. Seed 000 orders dV, dR, Psi, ...; the order here is
/// position first, which only permutes the matrices.
namespace tc17 {
inline constexpr StateBlock kPos{0, 3};
inline constexpr StateBlock kVel{3, 3};
inline constexpr StateBlock kAtt{6, 3};
inline constexpr StateBlock kAccelBias{9, 3};
inline constexpr StateBlock kGyroBias{12, 3};
inline constexpr StateBlock kClockBias{15, 1};
inline constexpr StateBlock kClockDrift{16, 1};
inline constexpr int kSize = 17;
static_assert(kPos.end() == kVel.index && kVel.end() == kAtt.index &&
                  kAtt.end() == kAccelBias.index && kAccelBias.end() == kGyroBias.index &&
                  kGyroBias.end() == kClockBias.index && kClockBias.end() == kClockDrift.index &&
                  kClockDrift.end() == kSize,
              "tc17 blocks must tile the state vector");
}  // namespace tc17

}  // namespace navbus::core
