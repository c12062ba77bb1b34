#include "navbus/core/filter/propagation_interval.hpp"

namespace navbus::core {

void PropagationInterval::add(const ErrorDynamicsBlocks& f, double dt_s, const StateVector& q) {
  if (increments_ == 0) {
    f_ = f;  // kept as the rate, so that a lone increment's transition is its own
    q_ = q;
  } else {
    if (increments_ == 1) f_ *= duration_s_;  // from here on the integral of F
    f_.addScaled(f, dt_s);
    q_ += q;
  }
  duration_s_ += dt_s;
  ++increments_;
}

StateMatrix PropagationInterval::transition() const {
  // transitionMatrix(F, dt) = I + F dt + (F dt)^2 / 2; the integral A is F with dt = 1.
  return increments_ == 1 ? transitionMatrix(errorDynamics(f_), duration_s_)
                          : transitionMatrix(errorDynamics(f_), 1.0);
}

void PropagationInterval::clear() {
  duration_s_ = 0.0;
  increments_ = 0;
}

}  // namespace navbus::core
