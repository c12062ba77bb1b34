#include "filter_node.hpp"

#include <chrono>
#include <sstream>

#include "navbus/bus/conversions.hpp"
#include "navbus/bus/topics.hpp"

namespace navbus::nav_filter {

namespace {

std::vector<InputSequencer<FilterInput>::ExpectedStream> expectedStreams(const FilterConfig& c) {
  std::vector<InputSequencer<FilterInput>::ExpectedStream> s;
  s.push_back({{kRankImu, c.imu.id}, c.imu.period_ns});
  if (c.gnss_observations)
    s.push_back({{kRankGnssObs, c.gnss_observations->id}, c.gnss_observations->period_ns});
  if (c.gnss_fix) s.push_back({{kRankGnssFix, c.gnss_fix->id}, c.gnss_fix->period_ns});
  if (c.star_tracker)
    s.push_back({{kRankStarTracker, c.star_tracker->id}, c.star_tracker->period_ns});
  return s;
}

std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

constexpr std::uint32_t kStreamLostFlags =
    navbus::FAULT_IMU_STREAM_LOST | navbus::FAULT_GNSS_STREAM_LOST | navbus::FAULT_ST_STREAM_LOST |
    navbus::FAULT_RAW_IMU_LOST;

}  // namespace

FilterNode::FilterNode(bus::Participant& p, const FilterConfig& config)
    : participant_(p),
      config_(config),
      sequencer_(expectedStreams(config), config.sequencer_max_wait_ns),
      imu_gate_(bus::topic::kImuIncrement, p.health().stream(bus::topic::kImuIncrement)),
      gnss_obs_gate_(bus::topic::kGnssObservations,
                     p.health().stream(bus::topic::kGnssObservations)),
      gnss_fix_gate_(bus::topic::kGnssFix, p.health().stream(bus::topic::kGnssFix)),
      star_gate_(bus::topic::kStarTracker, p.health().stream(bus::topic::kStarTracker)) {
  using namespace bus;
  solution_writer_ = p.createWriter<navbus::NavigationSolutionPubSubType>(topic::kNavSolution,
                                                                          profile::kSolutionWriter);
  if (config_.estimator == Estimator::kTightlyCoupled) {
    diagnostics_writer_ = p.createWriter<navbus::FilterDiagnosticsPubSubType>(
        topic::kFilterDiagnostics, profile::kDiagnosticsWriter);
  }
  p.subscribe<navbus::ImuIncrementPubSubType>(topic::kImuIncrement, profile::kSensorReader,
                                              [this](const auto& m, const auto&) { onImu(m); });
  p.subscribe<navbus::GnssObservationEpochPubSubType>(
      topic::kGnssObservations, profile::kMeasurementReader,
      [this](const auto& m, const auto&) { onGnssObservations(m); });
  p.subscribe<navbus::GnssFixPubSubType>(
      topic::kGnssFix, profile::kMeasurementReader, [this](const auto& m, const auto&) {
        onMeasurement(gnss_fix_gate_, m, m.receiver_id(), config_.gnss_fix, kRankGnssFix);
      });
  p.subscribe<navbus::StarTrackerAttitudePubSubType>(
      topic::kStarTracker, profile::kMeasurementReader, [this](const auto& m, const auto&) {
        onMeasurement(star_gate_, m, m.tracker_id(), config_.star_tracker, kRankStarTracker);
      });
  p.subscribe<navbus::FaultDecisionPubSubType>(
      topic::kFaultDecision, profile::kDecisionReader,
      [this](const auto& d, const auto&) { onDecision(d); });
  p.subscribe<navbus::FilterCommandPubSubType>(
      topic::kFilterCommand, profile::kDecisionReader,
      [this](const auto& c, const auto&) { onCommand(c); });
  // Bounded-wait release of inputs held for a silent stream, and the held solution while
  // inertial data is lost (the solution topic's deadline promises at least 1 Hz).
  p.setAfterDispatch([this] { pump(); });
  p.addTimer(std::chrono::milliseconds(20), [this] { pump(); });
  p.addTimer(std::chrono::nanoseconds(config.solution_period_ns), [this] {
    if (mode_ == navbus::MODE_INERTIAL_LOST) publishSolution();
  });
  reset();
}

void FilterNode::reset() {
  mode_ = navbus::MODE_INITIALIZING;
  fault_flags_ &= kStreamLostFlags;  // stream states are facts, not filter state
  accel_bias_b_mps2_.setZero();
  gyro_bias_b_radps_.setZero();
  excluded_satellites_.clear();
  ekf_ = core::TightlyCoupledEkf();
  updateState();
}

void FilterNode::queue(bus::StreamGate& gate, StreamId id, std::int64_t time_ns,
                       FilterInput input) {
  switch (sequencer_.push(id, time_ns, std::move(input))) {
    case InputSequencer<FilterInput>::PushResult::kQueued:
      break;
    case InputSequencer<FilterInput>::PushResult::kLate:
      gate.unaccept();
      gate.reject({navbus::REJECT_LATE, "time_gps_ns", static_cast<double>(time_ns)}, id.sensor_id);
      break;
    case InputSequencer<FilterInput>::PushResult::kUnexpected:
      gate.unaccept();
      gate.reject(
          {navbus::REJECT_UNEXPECTED_SOURCE, "sensor_id", static_cast<double>(id.sensor_id)},
          id.sensor_id);
      break;
  }
}

void FilterNode::onImu(const navbus::ImuIncrement& msg) {
  if (!imu_gate_.admit(msg, msg.sensor_id(), msg.seq(), msg.time_gps_ns())) return;
  queue(imu_gate_, {kRankImu, msg.sensor_id()}, static_cast<std::int64_t>(msg.time_gps_ns()),
        bus::toCore(msg));
}

template <class Sample>
void FilterNode::onMeasurement(bus::StreamGate& gate, const Sample& msg, std::uint32_t id,
                               const std::optional<InputConfig>& expected, StreamRank rank) {
  if (!gate.admit(msg, id, msg.seq(), msg.time_gps_ns())) return;
  if (!expected) {
    gate.unaccept();
    gate.reject({navbus::REJECT_UNEXPECTED_SOURCE, "sensor_id", static_cast<double>(id)}, id);
    return;
  }
  queue(gate, {rank, id}, static_cast<std::int64_t>(msg.time_gps_ns()), MeasurementEpoch{rank});
}

void FilterNode::pump() {
  sequencer_.release(steadyNowNs(), [this](StreamId id, std::int64_t t, const FilterInput& in) {
    process(id, t, in);
  });
}

void FilterNode::onGnssObservations(const navbus::GnssObservationEpoch& m) {
  if (!gnss_obs_gate_.admit(m, m.receiver_id(), m.seq(), m.time_gps_ns())) return;
  if (!config_.gnss_observations) {
    gnss_obs_gate_.unaccept();
    gnss_obs_gate_.reject(
        {navbus::REJECT_UNEXPECTED_SOURCE, "receiver_id", static_cast<double>(m.receiver_id())},
        m.receiver_id());
    return;
  }
  GnssEpochInput epoch;
  for (const auto& s : m.satellites()) {
    if (!s.valid()) continue;
    // Satellite clock corrections applied here, once: the core sees corrected measurements.
    epoch.satellites.push_back({s.sv_id(), bus::toVector(s.sat_pos_ecef_m()),
                                bus::toVector(s.sat_vel_ecef_mps()),
                                s.pseudorange_m() + s.sat_clock_correction_m(),
                                s.pseudorange_rate_mps() + s.sat_clock_drift_mps(),
                                s.pseudorange_sigma_m(), s.pseudorange_rate_sigma_mps()});
  }
  queue(gnss_obs_gate_, {kRankGnssObs, m.receiver_id()}, static_cast<std::int64_t>(m.time_gps_ns()),
        std::move(epoch));
}

void FilterNode::process(StreamId, std::int64_t, const FilterInput& input) {
  if (const auto* inc = std::get_if<core::ImuIncrement>(&input)) {
    integrate(*inc);
  } else if (const auto* epoch = std::get_if<GnssEpochInput>(&input)) {
    if (config_.estimator == Estimator::kTightlyCoupled) fuseGnss(*epoch);
  }
  // Other measurement epochs: validated and ordered, not fused by the estimators available yet.
}

void FilterNode::fuseGnss(const GnssEpochInput& epoch) {
  if (!ekf_.initialized() || mode_ == navbus::MODE_INERTIAL_LOST) return;
  GnssEpochInput used;
  for (const auto& s : epoch.satellites) {
    // Excluded satellites (by command) stay out; the diagnostics carry at most 24 satellites.
    if (excluded_satellites_.count(static_cast<std::uint16_t>(s.sv_id)) == 0 &&
        used.satellites.size() < 24) {
      used.satellites.push_back(s);
    }
  }
  if (used.satellites.empty()) return;
  ekf_.update(used.satellites);
  ++gnss_epochs_fused_;
  if (mode_ == navbus::MODE_INERTIAL_ONLY) mode_ = navbus::MODE_TIGHTLY_COUPLED;
  publishDiagnostics();
}

void FilterNode::publishDiagnostics() {
  const core::EpochDiagnostics& d = ekf_.lastEpoch();
  navbus::FilterDiagnostics msg;
  msg.vehicle_id(config_.vehicle_id);
  msg.seq(++diagnostics_seq_);
  msg.time_gps_ns(static_cast<std::uint64_t>(ekf_.state().time_ns));
  const auto m = static_cast<std::uint16_t>(d.h.rows());
  msg.n(static_cast<std::uint16_t>(core::tc17::kSize));
  msg.m(m);
  const std::pair<const char*, core::StateBlock> blocks[] = {
      {"pos_ned", core::tc17::kPos},           {"vel_ned", core::tc17::kVel},
      {"phi_ned", core::tc17::kAtt},           {"accel_bias", core::tc17::kAccelBias},
      {"gyro_bias", core::tc17::kGyroBias},    {"clock_bias", core::tc17::kClockBias},
      {"clock_drift", core::tc17::kClockDrift}};
  const char* units[] = {"m", "m/s", "rad", "m/s^2", "rad/s", "m", "m/s"};
  for (std::size_t i = 0; i < 7; ++i) {
    navbus::StateBlock b;
    b.name(blocks[i].first);
    b.index(static_cast<std::uint16_t>(blocks[i].second.index));
    b.dof(static_cast<std::uint16_t>(blocks[i].second.dof));
    b.unit(units[i]);
    msg.state_layout().push_back(b);
  }
  for (std::size_t r = 0; r < m; ++r) {
    navbus::MeasurementRow row;
    row.kind(d.is_rate[r] ? navbus::MEAS_PSEUDORANGE_RATE : navbus::MEAS_PSEUDORANGE);
    row.sv_id(static_cast<std::uint16_t>(d.sv_ids[r]));
    msg.rows().push_back(row);
    msg.innovation().push_back(d.innovation[static_cast<Eigen::Index>(r)]);
    msg.test_ratio().push_back(d.test_ratio[r]);
  }
  // Row-major matrices.
  for (Eigen::Index i = 0; i < d.innovation_cov.rows(); ++i)
    for (Eigen::Index j = 0; j < d.innovation_cov.cols(); ++j)
      msg.innovation_cov().push_back(d.innovation_cov(i, j));
  for (Eigen::Index i = 0; i < d.h.rows(); ++i)
    for (Eigen::Index j = 0; j < d.h.cols(); ++j) msg.h().push_back(d.h(i, j));
  for (Eigen::Index i = 0; i < d.k.rows(); ++i)
    for (Eigen::Index j = 0; j < d.k.cols(); ++j) msg.k().push_back(d.k(i, j));
  for (Eigen::Index i = 0; i < d.phi.rows(); ++i)
    for (Eigen::Index j = 0; j < d.phi.cols(); ++j) msg.phi().push_back(d.phi(i, j));
  diagnostics_writer_.write(msg);
}

void FilterNode::integrate(const core::ImuIncrement& raw_inc) {
  core::ImuIncrement inc = raw_inc;
  inc.delta_vel_b_mps -= accel_bias_b_mps2_ * inc.interval_s;
  inc.delta_angle_b_rad -= gyro_bias_b_radps_ * inc.interval_s;
  const auto interval_ns = static_cast<std::int64_t>(std::llround(inc.interval_s * 1e9));
  const std::int64_t start_ns = inc.time_ns - interval_ns;
  if (!ekf_.initialized()) {
    core::NavState s = config_.initial_state;
    s.time_ns = start_ns;
    ekf_.initialize(s, config_.initial_clock_bias_m, config_.initial_clock_drift_mps,
                    config_.tightly_coupled);
    next_output_ns_ = (start_ns / config_.solution_period_ns + 1) * config_.solution_period_ns;
  } else if (start_ns - ekf_.state().time_ns > interval_ns / 2) {
    // Inertial data is missing between the state time and this interval: nothing can be
    // propagated across the gap, so restart the integration and flag the solution.
    ekf_.restartAt(start_ns);
    fault_flags_ |= navbus::FAULT_IMU_GAP;
    ++imu_gaps_;
    next_output_ns_ = (start_ns / config_.solution_period_ns + 1) * config_.solution_period_ns;
  }
  ekf_.propagate(inc);
  ++imu_used_;
  if (mode_ == navbus::MODE_INITIALIZING || mode_ == navbus::MODE_INERTIAL_LOST) {
    // Back to inertial navigation; the tightly coupled mode resumes with the next GNSS epoch.
    mode_ = navbus::MODE_INERTIAL_ONLY;
    updateState();
  }
  if (ekf_.state().time_ns >= next_output_ns_) {
    publishSolution();
    next_output_ns_ =
        (ekf_.state().time_ns / config_.solution_period_ns + 1) * config_.solution_period_ns;
  }
}

void FilterNode::publishSolution() {
  if (!ekf_.initialized()) return;
  navbus::NavigationSolution sol;
  sol.vehicle_id(config_.vehicle_id);
  sol.seq(++solution_seq_);
  bus::fillSolution(ekf_.state(), sol);
  // Sigmas from the EKF covariance: propagated only (inertial-only mode) or updated.
  const core::Matrix17& P = ekf_.covariance();
  auto sigma3 = [&P](const core::StateBlock& b) {
    return bus::toArray(P.block<3, 3>(b.index, b.index).diagonal().cwiseSqrt());
  };
  sol.pos_sigma_ned_m(sigma3(core::tc17::kPos));
  sol.vel_sigma_ned_mps(sigma3(core::tc17::kVel));
  sol.att_sigma_ned_rad(sigma3(core::tc17::kAtt));
  sol.accel_bias_sigma_b_mps2(sigma3(core::tc17::kAccelBias));
  sol.gyro_bias_sigma_b_radps(sigma3(core::tc17::kGyroBias));
  sol.clock_bias_m(ekf_.clockBias());
  sol.clock_drift_mps(ekf_.clockDrift());
  sol.clock_bias_sigma_m(std::sqrt(P(core::tc17::kClockBias.index, core::tc17::kClockBias.index)));
  sol.clock_drift_sigma_mps(
      std::sqrt(P(core::tc17::kClockDrift.index, core::tc17::kClockDrift.index)));
  sol.covariance_valid(true);
  // Biases: estimated by the EKF plus those compensated by command.
  sol.accel_bias_b_mps2(bus::toArray(ekf_.accelBias() + accel_bias_b_mps2_));
  sol.gyro_bias_b_radps(bus::toArray(ekf_.gyroBias() + gyro_bias_b_radps_));
  sol.mode(mode_);
  sol.fusion(config_.estimator == Estimator::kTightlyCoupled ? navbus::FUSION_CENTRALIZED
                                                             : navbus::FUSION_NONE);
  sol.active_fault_flags(fault_flags_);
  sol.imu_samples_used(imu_used_);
  solution_writer_.write(sol);
}

void FilterNode::updateState() {
  participant_.setState((fault_flags_ & kStreamLostFlags) != 0 ? navbus::STATE_DEGRADED
                                                               : navbus::STATE_RUNNING);
}

void FilterNode::onDecision(const navbus::FaultDecision& d) {
  std::uint32_t flag = 0;
  bool is_imu = false;
  switch (d.source()) {
    case navbus::SOURCE_IMU_STREAM:
      if (d.sensor_id() != config_.imu.id) return;
      flag = navbus::FAULT_IMU_STREAM_LOST;
      is_imu = true;
      break;
    case navbus::SOURCE_IMU_RAW_STREAM:
      flag = navbus::FAULT_RAW_IMU_LOST;
      break;
    case navbus::SOURCE_GNSS_OBS_STREAM:
    case navbus::SOURCE_GNSS_FIX_STREAM:
      flag = navbus::FAULT_GNSS_STREAM_LOST;
      break;
    case navbus::SOURCE_ST_STREAM:
      flag = navbus::FAULT_ST_STREAM_LOST;
      break;
    default:
      spdlog::warn("decision {} ({}) concerns a detector this filter mode does not use; ignored",
                   d.decision_id(), d.detector());
      return;
  }
  ++decisions_applied_;
  if (d.action() == navbus::ACTION_STREAM_LOST) {
    fault_flags_ |= flag;
    if (is_imu) {
      sequencer_.setActive({kRankImu, config_.imu.id}, false);
      if (ekf_.initialized()) mode_ = navbus::MODE_INERTIAL_LOST;
    }
    spdlog::warn("decision {} ({}): stream source {} id {} lost; flags 0x{:x}", d.decision_id(),
                 d.detector(), static_cast<int>(d.source()), d.sensor_id(), fault_flags_);
  } else if (d.action() == navbus::ACTION_STREAM_RESTORED) {
    fault_flags_ &= ~flag;
    spdlog::info("decision {} ({}): stream source {} id {} restored; flags 0x{:x}", d.decision_id(),
                 d.detector(), static_cast<int>(d.source()), d.sensor_id(), fault_flags_);
  }
  updateState();
  if (mode_ == navbus::MODE_INERTIAL_LOST) publishSolution();
}

void FilterNode::onCommand(const navbus::FilterCommand& c) {
  if (c.vehicle_id() != config_.vehicle_id) return;
  bool applied = true;
  switch (c.kind()) {
    case navbus::CMD_EXCLUDE_SATELLITE:
      excluded_satellites_.insert(c.sv_id());
      fault_flags_ |= navbus::FAULT_SATELLITE_EXCLUDED;
      break;
    case navbus::CMD_READMIT_SATELLITE:
      excluded_satellites_.erase(c.sv_id());
      if (excluded_satellites_.empty()) fault_flags_ &= ~navbus::FAULT_SATELLITE_EXCLUDED;
      break;
    case navbus::CMD_COMPENSATE_BIAS:
      if (c.axis() > 2 || !std::isfinite(c.bias()) ||
          (c.sensor() != navbus::SOURCE_ACCELEROMETER && c.sensor() != navbus::SOURCE_GYRO)) {
        applied = false;
        break;
      }
      (c.sensor() == navbus::SOURCE_ACCELEROMETER ? accel_bias_b_mps2_
                                                  : gyro_bias_b_radps_)[c.axis()] += c.bias();
      fault_flags_ |= navbus::FAULT_SENSOR_AXIS;
      break;
    case navbus::CMD_SELECT_FUSION:
      // Run-time switching between structures is not available yet: only the configured one.
      applied = c.fusion() == (config_.estimator == Estimator::kTightlyCoupled
                                   ? navbus::FUSION_CENTRALIZED
                                   : navbus::FUSION_NONE);
      break;
    case navbus::CMD_SELECT_MODE:
      applied =
          c.mode() == navbus::MODE_INERTIAL_ONLY && config_.estimator == Estimator::kInertialOnly;
      break;
    case navbus::CMD_RESET:
      reset();
      break;
  }
  if (applied) {
    ++commands_applied_;
    spdlog::info("command {} from '{}' applied", c.command_id(), c.issuer());
  } else {
    ++commands_refused_;
    spdlog::warn(
        "command {} from '{}' refused: kind {} not available in mechanization-only mode or bad "
        "field",
        c.command_id(), c.issuer(), static_cast<int>(c.kind()));
  }
}

std::string FilterNode::summary() const {
  std::ostringstream out;
  out << "increments integrated " << imu_used_ << ", solutions published " << solution_seq_
      << ", inertial gaps " << imu_gaps_ << ", decisions applied " << decisions_applied_
      << ", commands applied " << commands_applied_ << " refused " << commands_refused_
      << ", GNSS epochs fused " << gnss_epochs_fused_ << ", sequencer timeouts "
      << sequencer_.timeouts() << ", pending " << sequencer_.pending();
  return out.str();
}

}  // namespace navbus::nav_filter
