// The covariance propagated over several IMU increments at once (FilterTuning::
// covariance_period_s). The mechanization runs every increment; the covariance waits until the
// filter needs it (a measurement, a solution epoch, a change of its structure, the period's
// end) and then takes one step over the interval T:
//   Phi = I + A + A^2 / 2,  A = sum_k F_k dt_k  (the integral of F over the increments),
//   Q = sum_k Q_k  (each increment's discrete process noise),
// and the Gauss-Markov states their exact decay exp(-T / tau) and driving noise over T.
// Against the product of the increments' own transitions (I + F_k dt_k + (F_k dt_k)^2 / 2)
// this leaves out terms of the second order in T that F's change within the interval makes
// (the commutators of F_i dt_i and F_j dt_j) and the first-order coupling of the interval's
// process noise through F; both are of the order of (|F| T)^2 of a step, about 1e-7 for
// T = 0.1 s where F's largest rates are the Earth's, the transport rate and a turning
// vehicle's specific force on attitude. docs/architecture.md gives the measured accuracy.
#pragma once

#include "navbus/core/filter/error_state.hpp"
#include "navbus/core/ins/ins_error_model.hpp"

namespace navbus::core {

class PropagationInterval {
 public:
  /// Adds one increment: F's blocks at its start, its interval [s] and its discrete process
  /// noise (the Gauss-Markov states' left to the caller, who knows their decay).
  void add(const ErrorDynamicsBlocks& f, double dt_s, const StateVector& q);
  bool empty() const { return increments_ == 0; }
  int increments() const { return increments_; }
  double duration_s() const { return duration_s_; }
  /// Phi over the interval; with one increment exactly that increment's transitionMatrix().
  StateMatrix transition() const;
  /// The summed discrete process noise.
  const StateVector& processNoise() const { return q_; }
  void clear();

 private:
  ErrorDynamicsBlocks f_;  ///< one increment: its F; more: the integral of F over them
  StateVector q_{StateVector::Zero()};
  double duration_s_{0.0};
  int increments_{0};
};

}  // namespace navbus::core
