// Offline evaluation without DDS: the scenario simulator feeds navbus-filter's pipeline
// directly (the same IDL conversions, validation, sequencing and engine as on the bus), and
// every solution is compared with the truth.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <navbus_idl/Common.h>
#include <navbus_idl/Fault.h>
#include <navbus_idl/Navigation.h>
#include <Eigen/Core>

#include "navbus/core/engine/initial_alignment.hpp"
#include "navbus/core/ins/strapdown.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/glr_detector.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"

namespace navbus::evaluation {

/// Estimate minus truth at one solution epoch, with the filter's own uncertainty.
inline constexpr int kNeesBlocks = 6;

struct EpochError {
  std::int64_t time_ns{0};
  Eigen::Vector3d pos_ned_m{Eigen::Vector3d::Zero()};
  Eigen::Vector3d vel_ned_mps{Eigen::Vector3d::Zero()};
  Eigen::Vector3d att_ned_rad{Eigen::Vector3d::Zero()};  ///< phi: C_est = (I - [phi x]) C_true
  Eigen::Vector3d pos_sigma_ned_m{Eigen::Vector3d::Zero()};
  Eigen::Vector3d vel_sigma_ned_mps{Eigen::Vector3d::Zero()};
  Eigen::Vector3d att_sigma_ned_rad{Eigen::Vector3d::Zero()};
  /// Bias estimates minus the simulator's biases [m/s^2, rad/s, rad; body / tracker axes].
  Eigen::Vector3d accel_bias_err_b_mps2{Eigen::Vector3d::Zero()};
  Eigen::Vector3d gyro_bias_err_b_radps{Eigen::Vector3d::Zero()};
  Eigen::Vector3d star_tracker_bias_err_b_rad{Eigen::Vector3d::Zero()};
  double nees9{0.0};  ///< position, velocity, attitude against the full 9x9 covariance
  /// NEES of each 3-state block against its own 3x3 covariance: position, velocity, attitude,
  /// accelerometer bias, gyro bias, star-tracker bias (NaN: a block the filter does not have).
  /// A bias's truth is the simulator's bias (scale factors and misalignments are not in it).
  Eigen::Matrix<double, kNeesBlocks, 1> nees_blocks{Eigen::Matrix<double, kNeesBlocks, 1>::Zero()};
  int mode{0};                  ///< navbus::FilterMode of the solution
  int integrity{0};             ///< navbus::IntegrityState of the solution
  double hpl_m{0.0};            ///< its horizontal protection level [m]
  double vpl_m{0.0};            ///< its vertical protection level [m]
  bool covariance_valid{true};  ///< the solution's own claim that its sigmas hold
};

struct OfflineSetup {
  sensor_sim::SimConfig sim;
  nav_filter::FilterConfig filter;
  /// The fault manager's pipeline in the same process (GLR on the filter's diagnostics, its
  /// commands to the filter); none: the filter runs alone.
  std::optional<fault_manager::FaultManagerConfig> fault_manager;
  double duration_s{0.0};  ///< of simulated data
  /// Keep every filter lane's solution (OfflineResult::lane_solutions; filter `lanes:`).
  bool keep_lane_solutions{false};
};

struct OfflineResult {
  std::vector<EpochError> errors;
  std::uint64_t solutions{0};
  std::uint64_t solutions_without_truth{0};  ///< solution times between truth samples
  /// Solutions published after the selected lane's engine had moved past them (lanes): not
  /// scored against the truth.
  std::uint64_t solutions_without_engine_state{0};
  std::vector<navbus::LaneSolution> lane_solutions;  ///< with keep_lane_solutions
  /// The fault manager's parity test (redundant IMUs), every 100 ms of data: the largest
  /// statistic of each kind over those samples and the thresholds.
  struct ParityEpoch {
    std::int64_t time_ns{0};
    double gyro{0.0}, accelerometer{0.0};
    double gyro_threshold{0.0}, accelerometer_threshold{0.0};
  };
  std::vector<ParityEpoch> parity_trace;
  std::string summary;  ///< the pipeline's counters
  /// The filter's refusals of IMU increments by reason (an IMU it was not configured with:
  /// REJECT_UNEXPECTED_SOURCE).
  std::map<navbus::RejectReason, std::uint64_t> imu_rejected;
  /// GNSS observation epochs the filter refused, by reason (e.g. a receiver it is not
  /// configured for: REJECT_UNEXPECTED_SOURCE).
  std::map<navbus::RejectReason, std::uint64_t> gnss_rejected;
  core::ConsistencyCounters consistency;  ///< the filter's test of its own innovations
  std::string fault_summary;              ///< the fault pipeline's counters
  std::vector<navbus::FaultDecision> decisions;
  /// Per decision: how many solutions had been published when it was (an alarm covers the
  /// solutions from this index on).
  std::vector<std::size_t> decision_after_solutions;
  std::vector<navbus::FilterCommand> commands;
  std::vector<std::size_t> command_after_solutions;  ///< per command, as for the decisions
  double max_glr_statistic{0.0};
  std::vector<fault_manager::GlrEpochStatistic>
      glr_trace;  ///< every epoch the GLR accepted, in order
  /// Configurations without an initial_state: what the alignment started from, and the error
  /// of that start against the truth at the same instant (its sigmas are the start's own).
  bool aligned{false};
  core::AlignedStart aligned_start;
  EpochError aligned_start_error;
};

using SolutionHook = std::function<void(const navbus::NavigationSolution&,
                                        const core::NavState& truth, const EpochError&)>;

/// Runs one scenario through the filter pipeline. hook (optional) sees every solution.
OfflineResult runOffline(const OfflineSetup& setup, const SolutionHook& hook = {});

/// The scenario's truth at its start time.
core::NavState initialTruth(const sim::ScenarioConfig& scenario);

/// An initial state drawn around `truth` from the filter's own initial sigmas (position,
/// velocity, level and heading), so that the Monte Carlo NEES tests the filter's claim.
core::NavState perturbedInitialState(const core::NavState& truth, const core::FilterTuning& t,
                                     std::uint64_t seed);

/// Estimate-minus-truth of position [m, NED], velocity and attitude (phi).
EpochError epochError(const core::NavState& estimate, const core::NavState& truth);

}  // namespace navbus::evaluation
