// Field lists of every navbus message, written once and used for text (echo) and CSV (record).
// visitFields(msg, v) calls, in declaration order:
//   v(name, value)       for scalars, enums, strings, fixed arrays and sequences of numbers;
//   v.rows(name, seq)    for the one sequence of structs a message may have (CSV: a row each;
//                        an element may have one of its own: a row per element of that);
//   v.text(name, str)    for nested structures summarized as text.
#pragma once

#include <sstream>
#include <string>
#include <type_traits>

#include <navbus_idl/Fault.h>
#include <navbus_idl/Gnss.h>
#include <navbus_idl/Health.h>
#include <navbus_idl/Imu.h>
#include <navbus_idl/Navigation.h>
#include <navbus_idl/StarTracker.h>

#include "navbus/bus/health.hpp"

namespace navbus::records {

/// visitFields(m, v) exists for M = T and M = const T: the same field list reads a message
/// (echo, record) and fills one (replay).
template <class M, class T>
using IfMessage = std::enable_if_t<std::is_same_v<std::remove_const_t<M>, T>>;

const char* enumName(navbus::FilterMode v);
const char* enumName(navbus::FusionStructure v);
const char* enumName(navbus::StartSource v);
const char* enumName(navbus::SolutionOutput v);
const char* enumName(navbus::IntegrityState v);
const char* enumName(navbus::FaultSource v);
const char* enumName(navbus::FaultEvent v);
const char* enumName(navbus::FaultShape v);
const char* enumName(navbus::SatelliteScope v);
const char* enumName(navbus::CommandKind v);
const char* enumName(navbus::CommandOutcomeKind v);
const char* enumName(navbus::ParticipantState v);
const char* enumName(navbus::MeasurementKind v);
inline const char* enumName(navbus::RejectReason v) {
  return bus::rejectReasonName(v);
}

template <class M, class V>
IfMessage<M, navbus::ImuIncrement> visitFields(M& m, V& v) {
  v("sensor_id", m.sensor_id());
  v("seq", m.seq());
  v("time_gps_ns", m.time_gps_ns());
  v("interval_ns", m.interval_ns());
  v("delta_vel_b_mps", m.delta_vel_b_mps());
  v("delta_angle_b_rad", m.delta_angle_b_rad());
  v("status_flags", m.status_flags());
}
template <class M, class V>
IfMessage<M, navbus::ImuIncrementBlock> visitFields(M& m, V& v) {
  v("sensor_id", m.sensor_id());
  v("seq", m.seq());
  v.rows("increments", m.increments());
}
template <class M, class V>
IfMessage<M, navbus::ImuRawSample> visitFields(M& m, V& v) {
  v("angular_rate_b_radps", m.angular_rate_b_radps());
  v("specific_force_b_mps2", m.specific_force_b_mps2());
}
template <class M, class V>
IfMessage<M, navbus::ImuRawBlock> visitFields(M& m, V& v) {
  v("sensor_id", m.sensor_id());
  v("seq", m.seq());
  v("first_sample_time_gps_ns", m.first_sample_time_gps_ns());
  v("sample_period_ns", m.sample_period_ns());
  v.rows("samples", m.samples());
}
template <class M, class V>
IfMessage<M, navbus::GnssSatelliteMeasurement> visitFields(M& m, V& v) {
  v("sv_id", m.sv_id());
  v("pseudorange_m", m.pseudorange_m());
  v("pseudorange_rate_mps", m.pseudorange_rate_mps());
  v("sat_pos_ecef_m", m.sat_pos_ecef_m());
  v("sat_vel_ecef_mps", m.sat_vel_ecef_mps());
  v("sat_clock_correction_m", m.sat_clock_correction_m());
  v("sat_clock_drift_mps", m.sat_clock_drift_mps());
  v("cn0_dbhz", m.cn0_dbhz());
  v("pseudorange_sigma_m", m.pseudorange_sigma_m());
  v("pseudorange_rate_sigma_mps", m.pseudorange_rate_sigma_mps());
  v("valid", m.valid());
}
template <class M, class V>
IfMessage<M, navbus::GnssObservationEpoch> visitFields(M& m, V& v) {
  v("receiver_id", m.receiver_id());
  v("seq", m.seq());
  v("time_gps_ns", m.time_gps_ns());
  v.rows("satellites", m.satellites());
}
template <class M, class V>
IfMessage<M, navbus::GnssObservationEpochBlock> visitFields(M& m, V& v) {
  v("receiver_id", m.receiver_id());
  v("seq", m.seq());
  v.rows("epochs", m.epochs());  // a row per satellite of each epoch
}
template <class M, class V>
IfMessage<M, navbus::GnssFix> visitFields(M& m, V& v) {
  v("receiver_id", m.receiver_id());
  v("seq", m.seq());
  v("time_gps_ns", m.time_gps_ns());
  v("latitude_rad", m.latitude_rad());
  v("longitude_rad", m.longitude_rad());
  v("height_m", m.height_m());
  v("pos_ecef_m", m.pos_ecef_m());
  v("vel_ned_mps", m.vel_ned_mps());
  v("pos_sigma_ned_m", m.pos_sigma_ned_m());
  v("vel_sigma_ned_mps", m.vel_sigma_ned_mps());
  v("num_satellites_used", m.num_satellites_used());
  v("valid", m.valid());
}
template <class M, class V>
IfMessage<M, navbus::StarTrackerAttitude> visitFields(M& m, V& v) {
  v("tracker_id", m.tracker_id());
  v("seq", m.seq());
  v("time_gps_ns", m.time_gps_ns());
  v("q_b_to_i", m.q_b_to_i());
  v("sigma_b_rad", m.sigma_b_rad());
  v("valid", m.valid());
}
template <class M, class V>
IfMessage<M, navbus::GnssFixBlock> visitFields(M& m, V& v) {
  v("receiver_id", m.receiver_id());
  v("seq", m.seq());
  v.rows("fixes", m.fixes());
}
template <class M, class V>
IfMessage<M, navbus::StarTrackerAttitudeBlock> visitFields(M& m, V& v) {
  v("tracker_id", m.tracker_id());
  v("seq", m.seq());
  v.rows("attitudes", m.attitudes());
}
/// A filter lane's solution: the lane, its selection, its fit, and the solution's navigation
/// fields (the rest of the solution is in navbus/nav/solution when the lane is selected).
template <class M, class V>
IfMessage<M, navbus::LaneSolution> visitFields(M& m, V& v) {
  v("vehicle_id", m.vehicle_id());
  v("lane_id", m.lane_id());
  v("selected", m.selected());
  v("available", m.available());
  v("test_ratio", m.test_ratio());
  v("named_faulty_for_decision", m.named_faulty_for_decision());
  auto& s = m.solution();
  v("seq", s.seq());
  v("time_gps_ns", s.time_gps_ns());
  v("latitude_rad", s.latitude_rad());
  v("longitude_rad", s.longitude_rad());
  v("height_m", s.height_m());
  v("vel_ned_mps", s.vel_ned_mps());
  v("roll_rad", s.roll_rad());
  v("pitch_rad", s.pitch_rad());
  v("yaw_rad", s.yaw_rad());
  v("pos_sigma_ned_m", s.pos_sigma_ned_m());
  v("vel_sigma_ned_mps", s.vel_sigma_ned_mps());
  v("att_sigma_ned_rad", s.att_sigma_ned_rad());
  v("gyro_bias_b_radps", s.gyro_bias_b_radps());
  v("mode", s.mode());
  v("covariance_valid", s.covariance_valid());
  v("active_fault_flags", s.active_fault_flags());
}
template <class M, class V>
IfMessage<M, navbus::NavigationSolution> visitFields(M& m, V& v) {
  v("vehicle_id", m.vehicle_id());
  v("seq", m.seq());
  v("time_gps_ns", m.time_gps_ns());
  v("latitude_rad", m.latitude_rad());
  v("longitude_rad", m.longitude_rad());
  v("height_m", m.height_m());
  v("pos_ecef_m", m.pos_ecef_m());
  v("vel_ned_mps", m.vel_ned_mps());
  v("q_b_to_n", m.q_b_to_n());
  v("roll_rad", m.roll_rad());
  v("pitch_rad", m.pitch_rad());
  v("yaw_rad", m.yaw_rad());
  v("pos_sigma_ned_m", m.pos_sigma_ned_m());
  v("vel_sigma_ned_mps", m.vel_sigma_ned_mps());
  v("att_sigma_ned_rad", m.att_sigma_ned_rad());
  v("clock_bias_m", m.clock_bias_m());
  v("clock_drift_mps", m.clock_drift_mps());
  v("clock_bias_sigma_m", m.clock_bias_sigma_m());
  v("clock_drift_sigma_mps", m.clock_drift_sigma_mps());
  v("accel_bias_b_mps2", m.accel_bias_b_mps2());
  v("gyro_bias_b_radps", m.gyro_bias_b_radps());
  v("accel_bias_sigma_b_mps2", m.accel_bias_sigma_b_mps2());
  v("gyro_bias_sigma_b_radps", m.gyro_bias_sigma_b_radps());
  v("accel_scale_b", m.accel_scale_b());
  v("gyro_scale_b", m.gyro_scale_b());
  v("accel_scale_sigma_b", m.accel_scale_sigma_b());
  v("gyro_scale_sigma_b", m.gyro_scale_sigma_b());
  v("mode", m.mode());
  v("fusion", m.fusion());
  v("covariance_valid", m.covariance_valid());
  v("active_fault_flags", m.active_fault_flags());
  v("imu_samples_used", m.imu_samples_used());
  v("start_source", m.start_source());
  v("integrity", m.integrity());
  v("horizontal_protection_level_m", m.horizontal_protection_level_m());
  v("vertical_protection_level_m", m.vertical_protection_level_m());
  v("output", m.output());
  v("propagated_from_gps_ns", m.propagated_from_gps_ns());
  v("lane_id", m.lane_id());
  v("reset_count", m.reset_count());
  v("reset_delta_pos_ned_m", m.reset_delta_pos_ned_m());
  v("reset_delta_vel_ned_mps", m.reset_delta_vel_ned_mps());
  v("reset_delta_att_ned_rad", m.reset_delta_att_ned_rad());
}
template <class M, class V>
IfMessage<M, navbus::FilterDiagnostics> visitFields(M& m, V& v) {
  v("vehicle_id", m.vehicle_id());
  v("seq", m.seq());
  v("time_gps_ns", m.time_gps_ns());
  v("n", m.n());
  v("m", m.m());
  std::ostringstream layout;
  for (const auto& b : m.state_layout())
    layout << b.name() << ":" << b.index() << "+" << b.dof() << "[" << b.unit() << "] ";
  v.text("state_layout", layout.str());
  std::ostringstream rows;
  for (const auto& r : m.rows())
    rows << enumName(r.kind()) << ":" << r.sv_id() << ":" << r.axis() << (r.used() ? "" : ":unused")
         << " ";
  v.text("rows", rows.str());
  v("innovation", m.innovation());
  v("innovation_cov", m.innovation_cov());
  v("h", m.h());
  v("k", m.k());
  v("phi", m.phi());
  v("test_ratio", m.test_ratio());
  std::ostringstream scales;
  for (const auto& n : m.noise_scales()) scales << enumName(n.stream()) << ":" << n.scale() << " ";
  v.text("noise_scales", scales.str());
  v("process_noise_scale", m.process_noise_scale());
}
template <class M, class V>
IfMessage<M, navbus::FaultDecision> visitFields(M& m, V& v) {
  v("decision_id", m.decision_id());
  v("time_gps_ns", m.time_gps_ns());
  v("event", m.event());
  v("source", m.source());
  v("sensor_id", m.sensor_id());
  v("sv_id", m.sv_id());
  v("axis", m.axis());
  v("shape", m.shape());
  v("test_statistic", m.test_statistic());
  v("threshold", m.threshold());
  v("magnitude", m.magnitude());
  v("onset_time_gps_ns", m.onset_time_gps_ns());
  v("ambiguous", m.ambiguous());
  std::ostringstream candidates;
  for (const auto& c : m.candidates()) {
    candidates << enumName(c.source()) << ":" << c.sv_id() << ":" << c.axis() << ":"
               << enumName(c.shape()) << ":" << c.statistic() << ":" << c.magnitude() << ":"
               << c.sensor_id() << " ";
  }
  v.text("candidates", candidates.str());
  v("detector", m.detector());
  v("dither_peak_frequency_hz", m.dither().peak_frequency_hz());
  v("dither_peak_amplitude", m.dither().peak_amplitude());
  v("dither_min_amplitude", m.dither().min_amplitude());
  v("dither_expected_frequency_hz", m.dither().expected_frequency_hz());
  v("dither_tolerance_hz", m.dither().tolerance_hz());
  v("dither_window_s", m.dither().window_s());
  v("run_id", m.run_id());
}
template <class M, class V>
IfMessage<M, navbus::FilterCommand> visitFields(M& m, V& v) {
  v("command_id", m.command_id());
  v("vehicle_id", m.vehicle_id());
  v("kind", m.kind());
  v("decision_id", m.decision_id());
  v("time_gps_ns", m.time_gps_ns());
  v("onset_time_gps_ns", m.onset_time_gps_ns());
  v("sv_id", m.sv_id());
  v("scope", m.scope());
  v("sensor", m.sensor());
  v("sensor_id", m.sensor_id());
  v("axis", m.axis());
  v("bias", m.bias());
  v("bias_sigma", m.bias_sigma());
  v("fusion", m.fusion());
  v("mode", m.mode());
  v("issuer", m.issuer());
  v("run_id", m.run_id());
}
template <class M, class V>
IfMessage<M, navbus::FilterCommandOutcome> visitFields(M& m, V& v) {
  v("vehicle_id", m.vehicle_id());
  v("command_id", m.command_id());
  v("issuer", m.issuer());
  v("run_id", m.run_id());
  v("kind", m.kind());
  v("outcome", m.outcome());
  v("reason", m.reason());
  v("detail", m.detail());
}
template <class M, class V>
IfMessage<M, navbus::FaultMonitorProgress> visitFields(M& m, V& v) {
  v("vehicle_id", m.vehicle_id());
  v("judged_up_to_gps_ns", m.judged_up_to_gps_ns());
  v("diagnostics_seq", m.diagnostics_seq());
  v("last_command_id", m.last_command_id());
  v("issuer", m.issuer());
  v("run_id", m.run_id());
  v("imu_judged_up_to_gps_ns", m.imu_judged_up_to_gps_ns());
  v("gnss_judged_up_to_gps_ns", m.gnss_judged_up_to_gps_ns());
}
template <class M, class V>
IfMessage<M, navbus::StreamHealth> visitFields(M& m, V& v) {
  v("topic", m.topic());
  v("received", m.received());
  v("accepted", m.accepted());
  v("sequence_gaps", m.sequence_gaps());
  v("deadline_misses", m.deadline_misses());
  v("source_restarts", m.source_restarts());
  std::ostringstream rejected;
  for (const auto& r : m.rejected()) rejected << enumName(r.reason()) << "=" << r.count() << " ";
  v.text("rejected", rejected.str());
  std::ostringstream elements;
  for (const auto& r : m.elements_rejected())
    elements << enumName(r.reason()) << "=" << r.count() << " ";
  v.text("elements_rejected", elements.str());
  std::ostringstream sensors;
  for (const auto& s : m.sensors())
    sensors << s.sensor_id() << ":accepted=" << s.accepted() << ",rejected=" << s.rejected()
            << ",sequence_gaps=" << s.sequence_gaps() << ",source_restarts=" << s.source_restarts()
            << " ";
  v.text("sensors", sensors.str());
  v("unlisted_sensor_samples", m.unlisted_sensor_samples());
}
template <class M, class V>
IfMessage<M, navbus::Health> visitFields(M& m, V& v) {
  v("participant", m.participant());
  v("seq", m.seq());
  v("wall_time_ns", m.wall_time_ns());
  v("state", m.state());
  v("samples_published", m.samples_published());
  v("resume_ns", m.resume_ns());
  v.rows("inputs", m.inputs());
}

}  // namespace navbus::records
