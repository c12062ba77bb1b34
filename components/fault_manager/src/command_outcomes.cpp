#include "navbus/fault_manager/command_outcomes.hpp"

namespace navbus::fault_manager {

bool CommandOutcomes::onOutcome(const navbus::FilterCommandOutcome& o) {
  if (o.issuer().to_string() != issuer_ || o.run_id() != run_id_) return false;
  switch (o.outcome()) {
    case navbus::OUTCOME_APPLIED:
      ++applied_;
      break;
    case navbus::OUTCOME_CLAMPED:
      ++clamped_;
      break;
    case navbus::OUTCOME_REFUSED:
      ++refused_;
      break;
  }
  if (notItsStream(o)) {
    ++not_its_streams_;
    return true;  // nothing of the filter's is left uncured
  }
  // Outcomes may come out of order (a command merged late answers after a later one): the
  // latest command decides.
  if (o.command_id() >= latest_command_id_) {
    latest_command_id_ = o.command_id();
    degraded_ = o.outcome() != navbus::OUTCOME_APPLIED;
  }
  return true;
}

bool CommandOutcomes::notItsStream(const navbus::FilterCommandOutcome& o) {
  return o.outcome() == navbus::OUTCOME_REFUSED && o.reason() == navbus::REJECT_UNEXPECTED_SOURCE &&
         (o.kind() == navbus::CMD_EXCLUDE_STREAM || o.kind() == navbus::CMD_READMIT_STREAM);
}

}  // namespace navbus::fault_manager
