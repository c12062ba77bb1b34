// Which satellite's time-correlated pseudorange error each state of layout::kPseudorangeError
// holds, and the estimate of each (the error-state filter keeps only the error of that estimate).
//
// A single-frequency receiver's pseudorange carries errors that last minutes: the ionosphere and
// troposphere the models leave, multipath around a slow antenna, orbit and clock errors of the
// broadcast ephemeris. Fused as white noise, epoch after epoch, they average into a confident
// position that is as far off as they are. Each one is modelled as a first-order Gauss-Markov
// process e' = -e / tau + w (stationary sigma, correlation time tau), one state per tracked
// satellite, so that the covariance keeps what averaging cannot remove.
//
// A satellite takes a free state when it first appears in an epoch and gives it up when an
// epoch no longer has it; a satellite that comes back starts again from the prior (its error
// is then taken as independent of what the filter learned: the state's correlations are
// dropped, never invented). With every state taken, a further satellite's pseudorange is fused
// with its white sigma only, and counted.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "navbus/core/ins/state_layout.hpp"

namespace navbus::core {

class PseudorangeErrorSlots {
 public:
  static constexpr int kSlots = layout::kPseudorangeError.dof;
  using Errors = Eigen::Matrix<double, kSlots, 1>;

  /// What assign() did for one epoch.
  struct Assignment {
    /// Per satellite of the epoch (same order): its state index in the layout, or -1 when
    /// every state was taken.
    std::vector<int> state_index;
    /// State indices that were given to a new satellite: their error and correlations must be
    /// reset to the prior.
    std::vector<int> fresh;
  };

  /// Forgets every satellite (a new run; unmodelled() keeps counting).
  void clear();
  /// A second receiver's clock takes the last two states (layout::kSecondClockBias): the
  /// satellites get the others only. Forgets every satellite.
  void leaveStatesToSecondClock(bool leave);
  /// States the satellites can take (kSlots, or kSlots - 2 beside a second receiver's clock).
  int slotsInUse() const { return slots_in_use_; }
  /// Releases the states of satellites not in `sv_ids`, then gives a state to each new one.
  /// Allocation-free after the first epochs (the vectors keep their capacity).
  const Assignment& assign(const std::vector<int>& sv_ids);

  /// The estimated error of the satellite in layout state `state_index` [m].
  double estimate(int state_index) const { return errors_m_[slot(state_index)]; }
  /// e = decay e: the expected value of the Gauss-Markov process one step on.
  void decay(double factor) { errors_m_ *= factor; }
  /// The error state dx (estimate minus truth) is removed from the estimates.
  void correct(const Errors& dx) { errors_m_.head(slots_in_use_) -= dx.head(slots_in_use_); }

  /// Satellite epochs whose pseudorange found no free state, since construction.
  std::uint64_t unmodelled() const { return unmodelled_; }
  /// The satellite in each slot, kFree for a free one.
  const std::array<int, kSlots>& satellites() const { return sv_of_slot_; }
  static constexpr int kFree = -1;

 private:
  static int slot(int state_index) { return state_index - layout::kPseudorangeError.index; }

  std::array<int, kSlots> sv_of_slot_{freeSlots()};
  static constexpr std::array<int, kSlots> freeSlots() {
    std::array<int, kSlots> a{};
    for (int& v : a) v = kFree;
    return a;
  }
  Errors errors_m_{Errors::Zero()};
  int slots_in_use_{kSlots};
  Assignment assignment_;
  std::uint64_t unmodelled_{0};
};

}  // namespace navbus::core
