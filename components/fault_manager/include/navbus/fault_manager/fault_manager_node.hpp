// navbus-fault-manager's participant: owns the readers and writers and feeds the DDS-free
// FaultPipeline (fault_pipeline.hpp). The DDS requested deadline and liveliness of the
// watchdog readers time the stream watchdogs; the diagnostics reader feeds the GLR.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include <fastdds/rtps/common/InstanceHandle.h>
#include <navbus_idl/FaultPubSubTypes.h>

#include "navbus/bus/participant.hpp"
#include "navbus/bus/writer_gate.hpp"
#include "navbus/fault_manager/fault_pipeline.hpp"

namespace navbus::fault_manager {

class FaultManagerNode {
 public:
  FaultManagerNode(bus::Participant& participant, const FaultManagerConfig& config);
  std::string summary() const { return pipeline_.summary(); }
  /// Called once the IMU stream's writer announced the end of its data.
  void setOnImuEnded(std::function<void()> fn) { on_imu_ended_ = std::move(fn); }

 private:
  template <class PubSubType, class IdFn, class TimeFn>
  void watch(const std::string& topic, const std::string& profile, StreamKind kind, IdFn id,
             TimeFn time);

  bus::Participant& participant_;
  std::function<void()> on_imu_ended_;
  bus::Writer<navbus::FaultDecision> decision_writer_;
  bus::Writer<navbus::FilterCommand> command_writer_;
  FaultPipeline pipeline_;
  /// DDS instance handle -> sensor id, per stream kind (deadline statuses name the instance).
  std::map<std::pair<StreamKind, eprosima::fastrtps::rtps::InstanceHandle_t>, std::uint32_t>
      instances_;
  /// One writer per sensor id on each watched stream (bus::WriterGate).
  std::map<std::string, bus::WriterGate> writers_;  ///< per topic
};

}  // namespace navbus::fault_manager
