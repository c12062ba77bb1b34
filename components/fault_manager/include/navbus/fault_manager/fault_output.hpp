// What a detector hands to the fault pipeline: decisions (facts) and commands (requests), see
// idl/Fault.idl. The pipeline stamps identities and issuer and sends them through its sinks.
#pragma once

#include <cstdint>

#include <navbus_idl/Fault.h>

namespace navbus::fault_manager {

class FaultOutput {
 public:
  virtual ~FaultOutput() = default;
  /// Stamps the decision id, publishes the decision and returns the id.
  virtual std::uint32_t decide(navbus::FaultDecision& d) = 0;
  /// Stamps command id, vehicle and issuer and publishes the command.
  virtual void command(navbus::FilterCommand& c) = 0;
};

}  // namespace navbus::fault_manager
