// Topic names and QoS profile names: the only place they are spelled.
// Profiles themselves live in qos/navbus_qos.xml.
#pragma once

namespace navbus::bus {

namespace topic {
inline constexpr const char* kImuIncrement = "navbus/imu/increment";
/// Blocks of increments (ImuIncrementBlock): the simulator's fast pacing.
inline constexpr const char* kImuIncrementBlock = "navbus/imu/increment_block";
inline constexpr const char* kImuRaw = "navbus/imu/raw";
inline constexpr const char* kGnssObservations = "navbus/gnss/observations";
inline constexpr const char* kGnssFix = "navbus/gnss/fix";
inline constexpr const char* kStarTracker = "navbus/startracker/attitude";
/// Blocks of epochs, fixes and attitudes (GnssObservationEpochBlock, GnssFixBlock,
/// StarTrackerAttitudeBlock): the simulator's fast pacing.
inline constexpr const char* kGnssObservationsBlock = "navbus/gnss/observations_block";
inline constexpr const char* kGnssFixBlock = "navbus/gnss/fix_block";
inline constexpr const char* kStarTrackerBlock = "navbus/startracker/attitude_block";
inline constexpr const char* kNavSolution = "navbus/nav/solution";
inline constexpr const char* kNavSolutionLowLatency = "navbus/nav/solution_low_latency";
/// Every filter lane's solution (redundant IMUs, filter `lanes:`), one instance per lane.
inline constexpr const char* kLaneSolution = "navbus/nav/lane_solution";
inline constexpr const char* kFilterDiagnostics = "navbus/nav/diagnostics";
inline constexpr const char* kFaultDecision = "navbus/fault/decision";
inline constexpr const char* kFilterCommand = "navbus/filter/command";
inline constexpr const char* kFaultProgress = "navbus/fault/progress";
inline constexpr const char* kCommandOutcome = "navbus/nav/command_outcome";
inline constexpr const char* kHealth = "navbus/health";
// Latency and throughput probes of `navbus latency` (ImuIncrement samples, sensor stream
// profiles unless the user names others).
inline constexpr const char* kLatencyPing = "navbus/latency/ping";
inline constexpr const char* kLatencyPong = "navbus/latency/pong";
}  // namespace topic

namespace profile {
// Participant profiles (transport / discovery choice).
inline constexpr const char* kParticipantLoopback = "navbus_participant_udp_loopback";
// Writer / reader profiles per topic class.
inline constexpr const char* kSensorWriter = "navbus_sensor_writer";
/// The simulator's sensor writers in fast pacing (same QoS, asynchronous publishing).
inline constexpr const char* kSensorWriterFastPacing = "navbus_sensor_writer_fast_pacing";
inline constexpr const char* kSensorReader = "navbus_sensor_reader";
inline constexpr const char* kSensorWatchdogReader = "navbus_sensor_watchdog_reader";
inline constexpr const char* kRawImuMonitorReader = "navbus_raw_imu_monitor_reader";
inline constexpr const char* kMeasurementWriter = "navbus_measurement_writer";
inline constexpr const char* kMeasurementWriterFastPacing = "navbus_measurement_writer_fast_pacing";
inline constexpr const char* kMeasurementReader = "navbus_measurement_reader";
inline constexpr const char* kMeasurementWatchdogReader = "navbus_measurement_watchdog_reader";
inline constexpr const char* kSolutionWriter = "navbus_solution_writer";
inline constexpr const char* kSolutionReader = "navbus_solution_reader";
inline constexpr const char* kLowLatencySolutionWriter = "navbus_low_latency_solution_writer";
inline constexpr const char* kLowLatencySolutionReader = "navbus_low_latency_solution_reader";
inline constexpr const char* kDecisionWriter = "navbus_decision_writer";
inline constexpr const char* kDecisionReader = "navbus_decision_reader";
inline constexpr const char* kProgressWriter = "navbus_progress_writer";
inline constexpr const char* kProgressReader = "navbus_progress_reader";
inline constexpr const char* kDiagnosticsWriter = "navbus_diagnostics_writer";
inline constexpr const char* kDiagnosticsReader = "navbus_diagnostics_reader";
inline constexpr const char* kHealthWriter = "navbus_health_writer";
inline constexpr const char* kHealthReader = "navbus_health_reader";
inline constexpr const char* kFoxgloveReader = "navbus_foxglove_reader";
}  // namespace profile

}  // namespace navbus::bus
