// navbus-filter configuration, converted to SI here.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "navbus/bus/imu_alignment.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/bus/validation.hpp"
#include "navbus/core/engine/navigation_engine.hpp"
#include "navbus/core/filter/lane_selector.hpp"
#include "navbus/core/ins/imu_mounting.hpp"
#include "navbus/core/integrity/lane_evidence.hpp"
#include "navbus/core/math/units.hpp"

namespace navbus::nav_filter {

struct InputConfig {
  std::uint32_t id{1};
  std::int64_t period_ns{0};
  /// Added to every sample's time as it enters the merge [ns]: a sensor whose stamps are late
  /// or early by a known delay (a logger's buffering, a receiver's output latency).
  std::int64_t time_offset_ns{0};
  /// gnss_fix only: the fix's velocity is valid at its (offset) time plus this [ns], negative
  /// for a receiver whose velocity lags its position (navbus calibrate time-offset).
  std::int64_t velocity_time_offset_ns{0};
  /// How long the stream may hold the ordered merge back before it is set aside [running ns]
  /// (0: sequencer_max_wait_s). Not a configuration key: the least-squares lane's IMU, which
  /// its lane set releases only once the fault manager has judged it, waits for that too.
  std::int64_t max_wait_ns{0};
};

/// The fault manager whose health reports (navbus/health) show that faults are monitored.
struct FaultMonitorWatch {
  std::string participant{"navbus-fault-manager"};  ///< Health.participant of its reports
  /// Under DDS Security: the certificate common name its reports must be written by (others
  /// are ignored and counted as unauthorized).
  std::string identity{"navbus-fault-manager"};
  std::int64_t timeout_ns{3'000'000'000};  ///< silence after which it is not alive [ns]
  /// How long the deterministic output waits for the monitor to judge a diagnostics epoch
  /// (FaultMonitorProgress) before it goes on without [ns]: longer than the monitor's stalls
  /// the output should ride through (a command that comes later is merged by rewinding).
  std::int64_t judgement_wait_ns{5'000'000'000};
  /// The monitor runs from the start: the output waits for its first judgement too (at most
  /// judgement_wait_ns if it never reports), not only once it has reported.
  bool judged_from_start{false};
  /// The monitor's cross-receiver test judges the receivers' epochs
  /// (FaultMonitorProgress.gnss_judged_up_to_gps_ns): an epoch is fused only once the time
  /// before it is judged, so that a clock jump or a satellite decided there is compensated or
  /// excluded before it, as offline (needs gnss_observations).
  bool receivers_judged{false};
};

/// One IMU of a filter with several (`lanes:`): it runs a lane of its own.
struct LaneUnit {
  std::uint32_t sensor_id{1};  ///< its increments' ImuIncrement.sensor_id
  /// Its axes into body axes (`mounting_rpy_deg`, the simulator's imu_units and the fault
  /// manager's parity.units convention: the unit's axes are the body's turned by roll, pitch and
  /// yaw, so v_b = dcmFromEuler(rpy) v_u).
  Eigen::Matrix3d c_b_u{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d lever_arm_b_m{Eigen::Vector3d::Zero()};  ///< its place from the body origin
};

/// Redundant IMUs (lane_set.hpp): one filter lane per unit, every lane fed every aiding
/// measurement, the published solution the selected lane's.
struct LanesConfig {
  std::vector<LaneUnit> units;  ///< empty: one lane, the `inputs.imu` IMU
  core::LaneSelectorConfig selector;
  /// Which of two suspect units failed (CMD_SUSPECT_SENSOR_AXIS, suspect_lanes.hpp).
  core::LaneEvidenceConfig evidence;
  /// Solutions the other lanes may be ahead of a lane that still speaks (one holding for its
  /// fault monitor lags) before it is passed over at those times (unavailable, counted): the
  /// bound on the memory the wait takes. A silent lane is passed over after
  /// sequencer_max_wait_s of running time.
  std::size_t max_pending{100000};
  /// `least_squares`: a further lane on the least-squares combination of every unit's
  /// instruments (combined_imu.hpp), with this lane id (its solutions' lane_id; not a unit's
  /// sensor_id); none when empty.
  std::optional<std::uint32_t> least_squares_lane_id;
  /// Increments one unit may hold waiting for another's before the combination goes on without
  /// the missing one (a reader hands out one unit's backlog before the next's: its history per
  /// instance; bus/imu_alignment.hpp).
  int least_squares_alignment_depth{static_cast<int>(bus::ImuUnitAligner::kReaderBacklog)};
  /// The selection starts on the least-squares lane and, when the lane it follows is left,
  /// goes back to it while it is available (LaneSelectorConfig::preferred).
  bool least_squares_preferred{false};
};

struct FilterConfig {
  core::EngineConfig engine;  ///< aiding mode, fusion structure, tuning, initial state
  std::uint32_t vehicle_id{1};
  InputConfig imu{1, 10'000'000};
  std::optional<InputConfig> gnss_observations;
  /// A second receiver whose pseudoranges the filter fuses beside gnss_observations.id's
  /// (inputs.gnss_observations.second_id; same period and time offset; its antenna
  /// geometry.second_antenna_lever_arm_b_m, its own clock states). Its epoch and the first's of
  /// the same time are fused as one stacked update.
  std::optional<std::uint32_t> second_gnss_receiver_id;
  std::optional<InputConfig> gnss_fix;
  std::optional<InputConfig> star_tracker;
  std::int64_t sequencer_max_wait_ns{500'000'000};
  /// Data time of every configured stream the ordered merge holds without allocating [ns]: a
  /// backlog after the filter was starved of CPU or stopped arrives at once. A larger one grows
  /// the buffer (an allocation on the processing thread, counted as "merge buffer grown").
  std::int64_t sequencer_reserve_ns{2'000'000'000};
  /// Recovery from a fault found late (input_history.hpp): data kept to restore the filter
  /// to before a fault's onset [ns] (0: off), and the spacing of the engine snapshots (each one
  /// a copy of the engine, 0.6 MB in the demo; the period sets how much a restore re-processes,
  /// not its result).
  std::int64_t recovery_history_ns{40'000'000'000};
  std::int64_t recovery_snapshot_period_ns{5'000'000'000};
  /// A satellite is excluded from this long before the estimated onset [ns].
  std::int64_t recovery_onset_margin_ns{5'000'000'000};
  /// Largest bias a CMD_COMPENSATE_BIAS may add [m/s^2, rad/s]; beyond, refused. A
  /// CMD_RELEARN_BIAS whose bias_sigma exceeds it re-learns up to it (counted).
  double max_accel_compensation_mps2{50.0 * units::kMilliG};
  double max_gyro_compensation_radps{200.0 * units::kDegPerHour};
  /// QoS profile of the solution writer (qos/navbus_qos.xml): navbus_solution_writer, or
  /// navbus_solution_writer_lossless for recording fast-paced runs.
  std::string solution_writer_profile{bus::profile::kSolutionWriter};
  /// QoS profile of the diagnostics writer: navbus_diagnostics_writer (the last 20 epochs for a
  /// reader that falls behind), or navbus_diagnostics_writer_lossless for recording fast-paced
  /// runs.
  std::string diagnostics_writer_profile{bus::profile::kDiagnosticsWriter};
  /// Issuers whose commands the filter accepts (FilterCommand.issuer); others are refused and
  /// counted. Without DDS Security the issuer is what the sender claims: this stops a
  /// misconfigured or stray tool, not an attacker (docs/security.md).
  std::vector<std::string> command_issuers{"fault-manager", "operator"};
  /// Under DDS Security: the certificate common name each issuer must be authenticated as
  /// (a command whose issuer is not the identity that wrote it is refused and counted). An
  /// issuer without an entry must be "navbus-<issuer>" (the test credentials' names).
  std::map<std::string, std::string> issuer_identities;
  /// A sample more than this ahead of every input's latest data is not believed until the
  /// samples after it confirm it (bus::TimeJumpRule).
  bus::TimeJumpRule time_jump{2'000'000'000, 3};
  /// On the bus: while no report of this fault monitor came for its timeout, solutions carry
  /// FAULT_NO_FAULT_MONITOR (nobody is detecting faults). Absent: the filter runs without one
  /// and says nothing about it.
  std::optional<FaultMonitorWatch> fault_monitor;
  /// The low-latency output (core/ins/output_predictor.hpp): the latest solution propagated with
  /// every IMU increment as it arrives, on its own topic; off unless configured.
  bool low_latency_output{false};
  /// Increments kept while the filter lags behind the newest one (at 200 Hz, 2 s).
  std::size_t low_latency_max_buffered{400};
  /// How the IMU's axes sit in the body (`geometry.imu_mounting_rpy_deg`): every increment is
  /// turned into body axes as it enters.
  core::ImuMounting imu_mounting;
  LanesConfig lanes;
};

/// Throws bus::ConfigError naming the key and the value on any invalid entry.
FilterConfig parseFilterConfig(const YAML::Node& root);

}  // namespace navbus::nav_filter
