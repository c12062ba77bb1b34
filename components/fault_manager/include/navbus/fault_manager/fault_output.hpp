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
  /// A detector excluded satellite sv_id for good, from every receiver (the cross-receiver
  /// test cannot say whose measurement was wrong): the other tests stop seeing it too.
  virtual void satelliteKeptOut(int sv_id) = 0;
};

/// CMD_FAIL_SENSOR_AXIS for the sensor, unit and axis a published decision names (its id, time
/// and onset), as the dither and parity detectors command it.
inline navbus::FilterCommand failAxisCommand(const navbus::FaultDecision& d) {
  navbus::FilterCommand c;
  c.kind(navbus::CMD_FAIL_SENSOR_AXIS);
  c.decision_id(d.decision_id());
  c.time_gps_ns(d.time_gps_ns());
  c.onset_time_gps_ns(d.onset_time_gps_ns());
  c.sensor(d.source());
  c.sensor_id(d.sensor_id());
  c.axis(d.axis());
  return c;
}

}  // namespace navbus::fault_manager
