// navbus-fault-manager's participant: owns the readers and writers and feeds the DDS-free
// FaultPipeline (fault_pipeline.hpp). The DDS requested deadline and liveliness of the
// watchdog readers time the stream watchdogs; the diagnostics reader feeds the GLR.
#pragma once

#include <cstdint>
#include <string>

#include <navbus_idl/FaultPubSubTypes.h>

#include "navbus/bus/participant.hpp"
#include "navbus/bus/sensor_readers.hpp"
#include "navbus/bus/stall_detector.hpp"
#include "navbus/bus/stop_after_end.hpp"
#include "navbus/fault_manager/fault_pipeline.hpp"

namespace navbus::fault_manager {

class FaultManagerNode {
 public:
  FaultManagerNode(bus::Participant& participant, const FaultManagerConfig& config);
  std::string summary() const { return pipeline_.summary(); }
  /// --exit-when-ended: told of the IMU stream's end (after the pipeline) and of its writers'
  /// liveliness.
  void stopAfterEnd(bus::StopAfterEnd& stop) { stop_after_end_ = &stop; }

 private:
  /// Watches the sensor topic of `Message` with the reader `profile` (its deadline).
  template <class Message>
  void watch(const char* profile);
  /// A block read by a watchdog reader: counted under its topic, each element received and
  /// watched as one sample of `element_topic`.
  template <class Block, class Elements>
  void watchElements(const Block& m, const char* element_topic, const Elements& elements,
                     const StreamWatchdog::WriterParticipant& writer);
  /// Ends the streams of a writer that announced the end of its data in its health report.
  void watchAnnouncedEnds();
  bus::SensorReaders::Events streamEvents();
  /// Reliable readers of every IMU's increments for the parity detector.
  void subscribeIncrements();
  /// The events of the detectors' own readers: a stream's end (after its last sample).
  bus::SensorReaders::Events detectorEvents();
  /// The steady clock now, after telling the pipeline of a stall of this process that just
  /// ended (bus::StallDetector).
  std::int64_t running();

  bus::Participant& participant_;
  bus::StopAfterEnd* stop_after_end_{nullptr};
  bus::Writer<navbus::FaultDecision> decision_writer_;
  bus::Writer<navbus::FilterCommand> command_writer_;
  bus::Writer<navbus::FaultMonitorProgress> progress_writer_;  ///< how far diagnostics are judged
  FaultPipeline pipeline_;
  bus::StallDetector stalls_;            ///< pauses of this process between two turns of its loop
  bus::SensorReaders sensors_;           ///< the watched sensor streams (owning writers only)
  bus::SensorReaders parity_sensors_;    ///< every IMU's increments, reliably (parity detector)
  bus::SensorReaders receiver_sensors_;  ///< every receiver's epochs, reliably (receiver detector)
};

}  // namespace navbus::fault_manager
