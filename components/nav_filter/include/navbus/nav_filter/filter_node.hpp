// navbus-filter's participant: DataReaders feed the filter pipeline (filter_pipeline.hpp),
// whose solutions and diagnostics go to DataWriters; timers bound the wait for silent streams
// and republish the held solution while inertial data is lost.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include <navbus_idl/NavigationPubSubTypes.h>

#include "navbus/bus/participant.hpp"
#include "navbus/bus/sensor_readers.hpp"
#include "navbus/bus/stall_detector.hpp"
#include "navbus/bus/stop_after_end.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/nav_filter/lane_set.hpp"
#include "navbus/nav_filter/monitor_liveness.hpp"

namespace navbus::nav_filter {

class FilterNode {
 public:
  FilterNode(bus::Participant& participant, const FilterConfig& config);

  /// Releases ready inputs (after every reader dispatch and periodically).
  void pump();
  std::string summary() const { return pipeline_.summary(); }
  /// --exit-when-ended: told of the IMU stream's end (after the pipeline) and of its writers'
  /// liveliness.
  void stopAfterEnd(bus::StopAfterEnd& stop) { stop_after_end_ = &stop; }

 private:
  /// STARTING until the first solution; DEGRADED while a stream is lost or no solution has
  /// been published for kNotProducingPeriods solution periods (at least kNotProducingMinNs):
  /// health never says RUNNING while the filter is not producing.
  void updateState();
  /// Follows the configured fault monitor's health reports (FilterConfig::fault_monitor).
  void watchFaultMonitor(const FaultMonitorWatch& watch);
  /// With fault_monitor.judged_from_start: the monitor starts with the filter, and the output
  /// waits for its judgement of the first epoch. So the inputs are taken only once it is
  /// connected (a progress writer has matched this filter's reader and, tightly coupled, a
  /// reader has matched the diagnostics; whose they are is not checked here, a recorder of the
  /// diagnostics counts too), at most `wait_ns`: the diagnostics are volatile, and an epoch
  /// published before the monitor's reader matched would never be judged (measured: under DDS
  /// Security the filter and the fault manager matched 1-3 s after the simulator's fast replay
  /// had started, and the GLR missed the demo's ramp).
  void awaitFaultMonitor(std::int64_t wait_ns, eprosima::fastdds::dds::DataReader& progress_reader,
                         bool diagnostics);
  bool faultMonitorConnected(eprosima::fastdds::dds::DataReader& progress_reader,
                             bool diagnostics) const;
  /// The sensor streams' readers (the simulator's fast pacing waits for them).
  void subscribeInputs();
  static constexpr std::chrono::milliseconds kMonitorPollPeriod{10};
  /// What the sensor readers tell the pipeline besides the samples: announced ends, liveliness.
  bus::SensorReaders::Events sensorEvents();
  static constexpr int kNotProducingPeriods = 3;
  static constexpr std::int64_t kNotProducingMinNs = 1'000'000'000;

  bus::Participant& participant_;
  bus::StopAfterEnd* stop_after_end_{nullptr};
  bus::Writer<navbus::NavigationSolution> solution_writer_;
  bus::Writer<navbus::FilterDiagnostics> diagnostics_writer_;
  bus::Writer<navbus::NavigationSolution> low_latency_writer_;  ///< when configured
  bus::Writer<navbus::FilterCommandOutcome> outcome_writer_;    ///< answers to commands
  bus::Writer<navbus::LaneSolution> lane_writer_;  ///< every lane's solutions (with `lanes:`)
  LaneSet pipeline_;
  std::int64_t not_producing_ns_;      ///< silence of the solution output that is "not producing"
  bus::StallDetector stalls_;          ///< pauses of this process between two pumps
  std::int64_t last_solution_ns_{-1};  ///< steady time of the latest solution written (-1: none)
  bus::SensorReaders sensors_;         ///< the sensor streams' readers (owning writers only)
  std::optional<MonitorLiveness> monitor_;       ///< the fault monitor's liveness, when configured
  std::optional<std::string> monitor_identity_;  ///< its writers' identity under DDS Security
};

}  // namespace navbus::nav_filter
