// navbus-fault-manager's participant logic: stream watchdogs on every sensor stream, turned
// into published fault decisions.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include <fastdds/rtps/common/InstanceHandle.h>
#include <navbus_idl/FaultPubSubTypes.h>

#include "navbus/bus/participant.hpp"
#include "navbus/bus/validation.hpp"
#include "stream_watchdog.hpp"

namespace navbus::fault_manager {

class FaultManagerNode {
 public:
  explicit FaultManagerNode(bus::Participant& participant);
  std::string summary() const;

 private:
  template <class PubSubType, class IdFn, class TimeFn>
  void watch(const std::string& topic, const std::string& profile, StreamKind kind, IdFn id,
             TimeFn time);
  void publish(const WatchdogEvent& e);

  bus::Participant& participant_;
  StreamWatchdog watchdog_;
  std::map<StreamKind, bus::SequenceTracker> trackers_;
  bus::Writer<navbus::FaultDecision> decision_writer_;
  std::map<StreamKind, double> deadline_s_;
  /// DDS instance handle -> sensor id, per stream kind (deadline statuses name the instance).
  std::map<std::pair<StreamKind, eprosima::fastrtps::rtps::InstanceHandle_t>, std::uint32_t>
      instances_;
  std::uint32_t next_decision_id_{1};
  std::uint64_t lost_decisions_{0};
  std::uint64_t restored_decisions_{0};
};

}  // namespace navbus::fault_manager
