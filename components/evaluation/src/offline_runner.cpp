#include "navbus/evaluation/offline_runner.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <random>
#include <type_traits>

#include <navbus_idl/Fault.h>

#include "navbus/bus/conversions.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/evaluation/frame_prefetcher.hpp"
#include "navbus/fault_manager/fault_pipeline.hpp"
#include "navbus/nav_filter/lane_set.hpp"
#include "navbus/sensor_sim/frame_publisher.hpp"
#include "navbus/sim/scenario_source.hpp"

namespace navbus::evaluation {

core::NavState initialTruth(const sim::ScenarioConfig& scenario) {
  return sim::ScenarioSource(scenario).truth();
}

core::NavState perturbedInitialState(const core::NavState& truth, const core::FilterTuning& t,
                                     std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  core::NavState s = truth;
  const Eigen::Vector3d dp(t.pos_sigma_m * n(rng), t.pos_sigma_m * n(rng), t.pos_sigma_m * n(rng));
  s.position = core::earth::offsetNed(s.position, dp);
  s.vel_ned_mps += Eigen::Vector3d(n(rng), n(rng), n(rng)) * t.vel_sigma_mps;
  const Eigen::Vector3d phi(t.level_sigma_rad * n(rng), t.level_sigma_rad * n(rng),
                            t.heading_sigma_rad * n(rng));
  // C_est = (I - [phi x]) C_true.
  s.q_b_to_n = (core::quaternionFromRotationVector(-phi) * s.q_b_to_n).normalized();
  return s;
}

EpochError epochError(const core::NavState& e, const core::NavState& t) {
  EpochError out;
  out.time_ns = e.time_ns;
  out.pos_ned_m = core::earth::differenceNed(e.position, t.position);
  out.vel_ned_mps = e.vel_ned_mps - t.vel_ned_mps;
  const Eigen::Matrix3d M =
      e.q_b_to_n.toRotationMatrix() * t.q_b_to_n.toRotationMatrix().transpose();
  out.att_ned_rad = Eigen::Vector3d(M(1, 2) - M(2, 1), M(2, 0) - M(0, 2), M(0, 1) - M(1, 0)) / 2.0;
  return out;
}

namespace {
/// The truth of one frame: navigation state and sensor biases.
struct Truth {
  core::NavState state;
  Eigen::Vector3d accel_bias_b_mps2;
  Eigen::Vector3d gyro_bias_b_radps;
  Eigen::Vector3d star_tracker_bias_b_rad;
  /// The further IMU units' biases in their own axes (SimConfig::extra_imu_sensor_ids order).
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> unit_biases_u{};  ///< accel, gyro
};

/// The truth as lane `unit`'s engine estimates it: its unit's biases turned into body axes
/// (the lane's increments are, by its mounting) and the position at the unit's place (the lane
/// integrates the motion there; the velocity's w x r is left out, as in the lane's
/// solution at the body origin).
Truth laneTruth(const Truth& t, const nav_filter::LaneUnit& unit,
                const sensor_sim::SimConfig& sim) {
  Truth out = t;
  const auto& ids = sim.extra_imu_sensor_ids;
  for (std::size_t k = 0; k < ids.size() && k < t.unit_biases_u.size(); ++k) {
    if (ids[k] != unit.sensor_id) continue;
    out.accel_bias_b_mps2 = unit.c_b_u * t.unit_biases_u[k].first;
    out.gyro_bias_b_radps = unit.c_b_u * t.unit_biases_u[k].second;
  }
  out.state.position =
      core::earth::offsetNed(t.state.position, t.state.q_b_to_n * unit.lever_arm_b_m);
  return out;
}

/// The truth as the least-squares lane's engine estimates it: the biases its combination carries
/// (E b of every unit's biases, in each unit's axes), at the body origin.
Truth combinedTruth(const Truth& t, const nav_filter::LaneSet& lanes,
                    const sensor_sim::SimConfig& sim) {
  Truth out = t;
  std::array<Eigen::Vector3d, core::ImuArrayCombination::kMaxUnits> accel{}, gyro{};
  const auto& ids = sim.extra_imu_sensor_ids;
  const core::ImuArrayCombination& c = lanes.combined()->combinationAt(t.state.time_ns);
  for (int u = 0; u < c.units(); ++u) {
    const nav_filter::LaneUnit& unit = lanes.laneUnit(u);
    const auto i = static_cast<std::size_t>(u);
    accel[i] = unit.c_b_u.transpose() * t.accel_bias_b_mps2;  // the scenario's IMU: body axes
    gyro[i] = unit.c_b_u.transpose() * t.gyro_bias_b_radps;
    for (std::size_t k = 0; k < ids.size() && k < t.unit_biases_u.size(); ++k) {
      if (ids[k] != unit.sensor_id) continue;
      accel[i] = t.unit_biases_u[k].first;
      gyro[i] = t.unit_biases_u[k].second;
    }
  }
  out.accel_bias_b_mps2 = c.combinedBias(core::ImuInstrument::kAccelerometer, accel);
  out.gyro_bias_b_radps = c.combinedBias(core::ImuInstrument::kGyro, gyro);
  return out;
}

/// The truth as the selected lane's engine estimates it.
Truth selectedLaneTruth(const Truth& t, const nav_filter::LaneSet& lanes,
                        const sensor_sim::SimConfig& sim) {
  const int k = lanes.selectedLane();
  if (lanes.combined() && k == lanes.lanes() - 1) return combinedTruth(t, lanes, sim);
  return laneTruth(t, lanes.laneUnit(k), sim);
}

/// NEES of one 3-state block of the error (estimate minus truth) against its covariance
/// block; NaN when the filter does not estimate the block.
double blockNees(const core::StateMatrix& P, const core::StateMask& active,
                 const core::StateBlock& b, const Eigen::Vector3d& error) {
  if (!active[static_cast<std::size_t>(b.index)]) return std::nan("");
  return error.dot(P.block<3, 3>(b.index, b.index).ldlt().solve(error));
}

/// The error of the engine's estimate against the truth, with its covariance's sigmas and NEES.
EpochError engineError(const core::NavigationEngine& engine, const Truth& truth) {
  EpochError err = epochError(engine.state(), truth.state);
  const core::StateMatrix& P = engine.covariance();
  using namespace core::layout;
  err.pos_sigma_ned_m = P.block<3, 3>(kPos.index, kPos.index).diagonal().cwiseSqrt();
  err.vel_sigma_ned_mps = P.block<3, 3>(kVel.index, kVel.index).diagonal().cwiseSqrt();
  err.att_sigma_ned_rad = P.block<3, 3>(kAtt.index, kAtt.index).diagonal().cwiseSqrt();
  Eigen::Matrix<double, 9, 1> d;
  d << err.pos_ned_m, err.vel_ned_mps, err.att_ned_rad;
  const Eigen::Matrix<double, 9, 9> P9 = P.topLeftCorner<9, 9>();
  err.nees9 = d.dot(P9.ldlt().solve(d));
  const core::StateMask& active = engine.activeStates();
  err.accel_bias_err_b_mps2 = engine.accelBias() - truth.accel_bias_b_mps2;
  err.gyro_bias_err_b_radps = engine.gyroBias() - truth.gyro_bias_b_radps;
  err.star_tracker_bias_err_b_rad = engine.starTrackerBias() - truth.star_tracker_bias_b_rad;
  err.nees_blocks << blockNees(P, active, kPos, err.pos_ned_m),
      blockNees(P, active, kVel, err.vel_ned_mps), blockNees(P, active, kAtt, err.att_ned_rad),
      blockNees(P, active, kAccelBias, err.accel_bias_err_b_mps2),
      blockNees(P, active, kGyroBias, err.gyro_bias_err_b_radps),
      blockNees(P, active, kStarTrackerBias, err.star_tracker_bias_err_b_rad);
  return err;
}

/// The error of a published solution against the truth, with its sigmas (no covariance: no
/// NEES, no bias errors).
EpochError messageError(const navbus::NavigationSolution& sol, const core::NavState& truth) {
  EpochError err = epochError(bus::toCore(sol), truth);
  const auto vec = [](const auto& a) { return Eigen::Vector3d(a[0], a[1], a[2]); };
  err.pos_sigma_ned_m = vec(sol.pos_sigma_ned_m());
  err.vel_sigma_ned_mps = vec(sol.vel_sigma_ned_mps());
  err.att_sigma_ned_rad = vec(sol.att_sigma_ned_rad());
  const double nan = std::nan("");
  err.nees9 = nan;
  err.accel_bias_err_b_mps2.setConstant(nan);
  err.gyro_bias_err_b_radps.setConstant(nan);
  err.star_tracker_bias_err_b_rad.setConstant(nan);
  err.nees_blocks.setConstant(nan);
  return err;
}

/// The parity test's statistics, the largest of every 100 ms of data (OfflineResult::parity_trace).
void traceParity(const fault_manager::ParityDetector& parity, std::int64_t time_ns,
                 OfflineResult& result) {
  constexpr std::int64_t kPeriodNs = 100'000'000;
  auto& trace = result.parity_trace;
  const std::int64_t slot = (time_ns + kPeriodNs - 1) / kPeriodNs * kPeriodNs;
  if (trace.empty() || trace.back().time_ns != slot) trace.push_back({slot});
  OfflineResult::ParityEpoch& e = trace.back();
  const auto& latest = parity.latest();
  e.gyro = std::max(e.gyro, latest.statistic[0]);
  e.accelerometer = std::max(e.accelerometer, latest.statistic[1]);
  e.gyro_threshold = parity.array().threshold(core::ImuInstrument::kGyro);
  e.accelerometer_threshold = parity.array().threshold(core::ImuInstrument::kAccelerometer);
}

/// Once, when the engine has just aligned: its start against the truth at the start's time.
void recordAlignedStart(const core::NavigationEngine& engine, const std::deque<Truth>& truths,
                        OfflineResult& result) {
  if (result.aligned || engine.alignmentPhase() != core::AlignmentPhase::kAligned) return;
  const core::AlignedStart& a = engine.alignedStart();
  for (const Truth& truth : truths) {
    const core::NavState& t = truth.state;
    if (t.time_ns != a.state.time_ns) continue;
    result.aligned = true;
    result.aligned_start = a;
    EpochError& e = result.aligned_start_error;
    e = epochError(a.state, t);
    e.pos_sigma_ned_m = a.pos_sigma_ned_m;
    e.vel_sigma_ned_mps = a.vel_sigma_ned_mps;
    e.att_sigma_ned_rad = a.att_sigma_ned_rad;
    return;
  }
}
}  // namespace

OfflineResult runOffline(const OfflineSetup& setup, const SolutionHook& hook) {
  OfflineResult result;
  const sensor_sim::SimConfig& sim = setup.sim;
  // One error per solution: reserved, so that the vector does not double past what it needs.
  result.errors.reserve(static_cast<std::size_t>(
      setup.duration_s * 1e9 / static_cast<double>(setup.filter.engine.solution_period_ns) + 2));
  sim::ScenarioSource source(sim.scenario);
  bus::HealthCounters health("navbus-offline");
  std::deque<Truth> truths;
  const nav_filter::LaneSet* pipeline_ptr = nullptr;
  auto on_solution = [&](const navbus::NavigationSolution& sol) {
    ++result.solutions;
    const auto t = static_cast<std::int64_t>(sol.time_gps_ns());
    while (!truths.empty() && truths.front().state.time_ns < t) truths.pop_front();
    if (truths.empty() || truths.front().state.time_ns != t) {
      ++result.solutions_without_truth;
      return;
    }
    const core::NavigationEngine& engine = pipeline_ptr->engine();
    const auto& units = setup.filter.lanes.units;
    // One lane: the frame's truth as it is (no copy per solution).
    std::optional<Truth> lane_truth;
    if (!units.empty()) lane_truth = selectedLaneTruth(truths.front(), *pipeline_ptr, sim);
    const Truth& truth = lane_truth ? *lane_truth : truths.front();
    // With lanes, the selection waits for the slowest lane: the selected lane's engine may have
    // moved on (its covariance at this time is gone). Scored from the message then (at the body
    // origin, its sigmas; no NEES, no bias errors), and counted. The engine, when it is there,
    // against the truth at its unit's place and that unit's biases.
    EpochError err = engine.state().time_ns == t ? engineError(engine, truth)
                                                 : messageError(sol, truths.front().state);
    result.solutions_without_engine_state += engine.state().time_ns == t ? 0 : 1;
    err.mode = static_cast<int>(sol.mode());
    err.integrity = static_cast<int>(sol.integrity());
    err.covariance_valid = sol.covariance_valid();
    err.hpl_m = sol.horizontal_protection_level_m();
    err.vpl_m = sol.vertical_protection_level_m();
    result.errors.push_back(err);
    if (hook) hook(sol, truths.front().state, err);
  };
  // The fault manager's pipeline, when configured, sees every diagnostics sample as the
  // filter emits it and its commands go back to the filter at once.
  std::optional<fault_manager::FaultPipeline> faults;
  nav_filter::LaneSet* filter_ptr = nullptr;
  // How far the fault manager has judged: to the filter after each frame, as its reader takes
  // them on the bus (a filter that waits for judgements from the start waits offline too).
  std::vector<navbus::FaultMonitorProgress> progress;
  if (setup.fault_manager) {
    faults.emplace(*setup.fault_manager, health,
                   fault_manager::FaultPipeline::Sinks{
                       [&](const navbus::FaultDecision& d) {
                         result.decisions.push_back(d);
                         result.decision_after_solutions.push_back(result.errors.size());
                       },
                       [&](const navbus::FilterCommand& c) {
                         result.commands.push_back(c);
                         result.command_after_solutions.push_back(result.errors.size());
                         filter_ptr->onCommand(c);
                       },
                       [&](const navbus::FaultMonitorProgress& p) { progress.push_back(p); }});
  }
  std::function<void(const navbus::FilterDiagnostics&)> on_diagnostics;
  if (faults) {
    on_diagnostics = [&](const navbus::FilterDiagnostics& d) {
      if (faults->onDiagnostics(d)) result.glr_trace.push_back(faults->glr().latest());
    };
  }
  std::function<void(const navbus::FilterCommandOutcome&)> on_outcome;
  if (faults)
    on_outcome = [&](const navbus::FilterCommandOutcome& o) { faults->onCommandOutcome(o); };
  std::function<void(const navbus::LaneSolution&)> on_lane;
  if (setup.keep_lane_solutions || faults)
    on_lane = [&](const navbus::LaneSolution& l) {
      if (setup.keep_lane_solutions) result.lane_solutions.push_back(l);
      if (faults) faults->onLaneSolution(l);
    };
  nav_filter::LaneSet pipeline(setup.filter, health,
                               {{on_solution, on_diagnostics, nullptr, on_outcome}, on_lane});
  pipeline_ptr = &pipeline;
  filter_ptr = &pipeline;

  const auto period_ns = sim.scenario.imu_period_ns;
  const auto total = static_cast<std::int64_t>(
      std::llround(setup.duration_s * 1e9 / static_cast<double>(period_ns)));
  sensor_sim::FrameSequence seq;
  auto feed = [&pipeline, &faults](const auto& sample) {
    using T = std::decay_t<decltype(sample)>;
    if constexpr (std::is_same_v<T, navbus::ImuIncrement>) {
      pipeline.onImu(sample);
      if (faults) faults->onImuIncrement(sample);
    }
    if constexpr (std::is_same_v<T, navbus::GnssObservationEpoch>) {
      pipeline.onGnssObservations(sample);
      if (faults) faults->onGnssEpoch(sample);
    }
    if constexpr (std::is_same_v<T, navbus::GnssFix>) pipeline.onGnssFix(sample);
    if constexpr (std::is_same_v<T, navbus::StarTrackerAttitude>) pipeline.onStarTracker(sample);
    if constexpr (std::is_same_v<T, navbus::ImuRawBlock>) faults->onRawBlock(sample);
    return true;
  };
  sensor_sim::SimConfig emitted = sim;
  // Raw blocks only feed the fault manager's dither monitor.
  emitted.publish_raw = sim.publish_raw && faults && faults->dither().has_value();
  FramePrefetcher frames(source, total);
  while (const sim::SensorFrame* next = frames.next()) {
    const sim::SensorFrame& f = *next;
    truths.push_back({f.truth, f.truth_accel_bias_b_mps2, f.truth_gyro_bias_b_radps,
                      f.truth_star_tracker_bias_b_rad});
    for (const sim::UnitImuIncrement& u : f.extra_imus)
      truths.back().unit_biases_u.emplace_back(u.truth_accel_bias_u_mps2,
                                               u.truth_gyro_bias_u_radps);
    // The same samples, in the same order and with the same sequence numbers as the
    // simulator participant publishes them.
    sensor_sim::emitFrame(f, emitted, seq, feed);
    for (const navbus::FaultMonitorProgress& p : progress) pipeline.onFaultMonitorProgress(p);
    progress.clear();
    // Data time bounds the wait for a silent stream (the bus uses steady time).
    pipeline.pump(f.increment.time_ns);
    if (faults && faults->parity()) traceParity(*faults->parity(), f.increment.time_ns, result);
    recordAlignedStart(pipeline.engine(), truths, result);
  }
  // End of data: whatever waits for a stream that will not speak again is released.
  pipeline.flush(sim.scenario.start_time_ns + total * period_ns);
  result.summary = pipeline.summary();
  if (const bus::StreamCounters* imu = health.find(bus::topic::kImuIncrement))
    result.imu_rejected = imu->rejected;
  if (const bus::StreamCounters* gnss = health.find(bus::topic::kGnssObservations))
    result.gnss_rejected = gnss->rejected;
  result.consistency = pipeline.engine().consistency().counters();
  if (faults) {
    result.fault_summary = faults->summary();
    result.max_glr_statistic = faults->glr().counters().max_statistic;
  }
  return result;
}

}  // namespace navbus::evaluation
