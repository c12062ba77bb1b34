#include "navbus/core/engine/navigation_engine.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "navbus/core/engine/initial_alignment.hpp"
#include "navbus/core/filter/integrated_filter.hpp"
#include "navbus/core/filter/multi_dimensional.hpp"
#include "navbus/core/integrity/glr_protection_level.hpp"

namespace navbus::core {

using namespace layout;

namespace {
EngineMode stageMode(MdfStage s) {
  switch (s) {
    case MdfStage::kF1ZeroVelocity:
      return EngineMode::kMdfF1;
    case MdfStage::kF2Gnss:
      return EngineMode::kMdfF2;
    case MdfStage::kF3Recovery:
      return EngineMode::kMdfF3;
    case MdfStage::kF4Constraint:
      return EngineMode::kMdfF4;
  }
  return EngineMode::kMdfF2;
}
}  // namespace

NavigationEngine::NavigationEngine(const EngineConfig& config)
    : config_(config),
      filter_(std::in_place),
      aligner_(std::in_place, config.alignment),
      integrity_(std::in_place),
      stationarity_(std::in_place),
      stages_(std::in_place) {
  integrity_->configure(config.integrity);
  consistency_.configure(config.consistency);
  for (std::size_t i = 0; i < noise_scales_.size(); ++i) {
    NoiseScaleConfig stream = config.adaptive_noise;
    stream.enabled = stream.enabled && config.adaptive_noise_streams[i];
    noise_scales_[i].configure(stream);
  }
  process_noise_.configure(config.adaptive_process_noise);
  used_->reserve(32);
  first_receiver_->reserve(32);
  held_.satellites.reserve(static_cast<std::size_t>(kMaxEpochSatellites));
  reset();
}

NavigationEngine::NavigationEngine(const NavigationEngine& other) = default;
NavigationEngine::NavigationEngine(NavigationEngine&& other) noexcept = default;
NavigationEngine& NavigationEngine::operator=(const NavigationEngine& other) = default;
NavigationEngine& NavigationEngine::operator=(NavigationEngine&& other) noexcept = default;
NavigationEngine::~NavigationEngine() = default;

bool NavigationEngine::initialized() const {
  return filter_->initialized();
}
const NavState& NavigationEngine::state() const {
  return filter_->state();
}
const StateMatrix& NavigationEngine::covariance() const {
  return filter_->covariance();
}
const StateMask& NavigationEngine::activeStates() const {
  return filter_->active();
}
Eigen::Vector3d NavigationEngine::accelBias() const {
  return filter_->accelBias() + accel_compensation_;
}
Eigen::Vector3d NavigationEngine::gyroBias() const {
  return filter_->gyroBias() + gyro_compensation_;
}
ImuCorrection NavigationEngine::imuCorrection() const {
  ImuCorrection c = filter_->imuCorrection();
  c.accel_bias_b_mps2 += accel_compensation_;
  c.gyro_bias_b_radps += gyro_compensation_;
  return c;
}
Eigen::Vector3d NavigationEngine::starTrackerBias() const {
  return filter_->starTrackerBias();
}
Eigen::Vector3d NavigationEngine::mountingMisalignment() const {
  return filter_->mountingMisalignment();
}
bool NavigationEngine::modelsMountingMisalignment() const {
  return filter_->modelsMountingMisalignment();
}
double NavigationEngine::clockBias(int receiver) const {
  return filter_->clockBias(receiver);
}
double NavigationEngine::clockDrift(int receiver) const {
  return filter_->clockDrift(receiver);
}
FusionStructure NavigationEngine::fusion() const {
  return filter_->structure();
}
const EpochDiagnostics& NavigationEngine::lastEpoch() const {
  return filter_->lastEpoch();
}
AlignmentPhase NavigationEngine::alignmentPhase() const {
  return aligner_->phase();
}
const AlignedStart& NavigationEngine::alignedStart() const {
  return aligner_->start();
}
std::uint64_t NavigationEngine::alignmentFailedSolutions() const {
  return aligner_->failedSolutions();
}
std::uint64_t NavigationEngine::protectionLevelEpochs() const {
  return integrity_->epochs();
}
std::uint64_t NavigationEngine::protectionLevelEpochsRefused() const {
  return integrity_->refused();
}
std::uint64_t NavigationEngine::protectionLevelDetections() const {
  return integrity_->detections();
}
bool NavigationEngine::aligning() const {
  return config_.start == StartSource::kAligned && !filter_->initialized();
}

void NavigationEngine::closeSmoothingLog() {
  filter_->closeSmoothingRecord();
}

void NavigationEngine::reset() {
  *filter_ = IntegratedFilter();
  *aligner_ = InitialAligner(config_.alignment);
  integrity_->reset();
  mode_ = EngineMode::kInitializing;
  status_ = 0;
  failed_axes_ = 0;
  excluded_.clear();
  accel_compensation_.setZero();
  gyro_compensation_.setZero();
  last_fix_ns_ = -1;
  last_fix_moving_speed_mps_ = 0.0;
  course_check_armed_ = false;
  stationarity_->configure(config_.mdf.stationarity, config_.imu_period_s);
  stages_->configure(config_.mdf);
  stages_->restart();
  consistency_.restart();
  for (NoiseScaleEstimator& n : noise_scales_) n.restart();
  process_noise_.restart();
}

std::uint64_t NavigationEngine::pseudorangesWithoutErrorState() const {
  return filter_->pseudorangeErrors().unmodelled();
}

StateMask NavigationEngine::baseMask() const {
  StateMask m = maskOf({kPos, kVel, kAtt, kAccelBias, kGyroBias});
  // The IMU's scale factors, where they are modelled.
  if (config_.tuning.accel_scale_sigma > 0.0) m |= maskOf({kAccelScale});
  if (config_.tuning.gyro_scale_sigma > 0.0) m |= maskOf({kGyroScale});
  // The receiver clock is a state only when pseudoranges are used.
  if (config_.aiding == AidingMode::kTightlyCoupled ||
      config_.aiding == AidingMode::kInertialOnly) {
    m |= maskOf({kClockBias, kClockDrift});
    if (config_.fused_receivers > 1) m |= maskOf({kSecondClockBias, kSecondClockDrift});
    if (config_.tuning.pseudorange_error_sigma_m > 0.0) m |= maskOf({kPseudorangeError});
    return m;
  }
  // The star tracker's bias where it is modelled and the tracker used.
  if (config_.use_star_tracker && config_.tuning.star_tracker_bias_sigma_rad > 0.0)
    m |= maskOf({kStarTrackerBias});
  // A land vehicle's mounting misalignment, where it is modelled (the non-holonomic
  // constraint's, in the multi-dimensional filter).
  if (config_.aiding == AidingMode::kMultiDimensional &&
      config_.tuning.mounting_misalignment_sigma_rad > 0.0)
    m |= maskOf({kMountingMisalignment});
  // The fix's time-correlated position error, where it is modelled (loose coupling).
  if (config_.tuning.fix_position_error_sigma_h_m > 0.0) m |= maskOf({kFixPositionError});
  return m;
}

bool NavigationEngine::addImu(const ImuIncrement& raw) {
  ImuIncrement inc = raw;
  inc.delta_vel_b_mps -= accel_compensation_ * inc.interval_s;
  inc.delta_angle_b_rad -= gyro_compensation_ * inc.interval_s;
  if (!(inc.interval_s > 0.0 && inc.interval_s < 1.0) || !inc.delta_vel_b_mps.allFinite() ||
      !inc.delta_angle_b_rad.allFinite()) {
    ++counters_.imu_refused;
    return false;
  }
  if (aligning()) {
    aligner_->addImu(inc);
    ++counters_.imu_aligning;
    mode_ = EngineMode::kAligning;
    if (aligner_->aligned()) startFromAlignment();  // at the end of this increment
    // Every input is taken by the aligner until it has aligned; the filter starts at the time
    // of the latest increment it took, so the next one continues without a gap.
    return false;
  }
  const auto interval_ns = static_cast<std::int64_t>(std::llround(inc.interval_s * 1e9));
  const std::int64_t start_ns = inc.time_ns - interval_ns;
  const std::int64_t period = config_.solution_period_ns;
  if (filter_->initialized() && start_ns < filter_->state().time_ns - interval_ns / 2) {
    ++counters_.imu_refused;  // overlaps or precedes what is already integrated
    return false;
  }
  if (!filter_->initialized()) {
    NavState s = config_.initial_state;
    s.time_ns = start_ns;
    const StateVector sigma = IntegratedFilter::initialSigma(config_.tuning);
    start(s, config_.initial_clock_bias_m, config_.initial_clock_drift_mps,
          sigma.array().square().matrix().asDiagonal());
  } else if (start_ns - filter_->state().time_ns > interval_ns / 2) {
    crossGap(start_ns);  // inertial data is missing between the state time and this interval
  }
  last_increment_ = inc;
  // Seed 004's comparison cases stop the filter during an outage (the mechanization runs on);
  // it resumes with the covariance it had (case I) or a re-initialized one (case II).
  const bool suspended = config_.aiding == AidingMode::kMultiDimensional &&
                         config_.mdf.policy != MdfPolicy::kMultiDimensional &&
                         stages_->stage() == MdfStage::kF4Constraint;
  const Eigen::Vector3d vel_before_ned_mps = filter_->state().vel_ned_mps;
  filter_->propagate(inc, suspended);
  velocity_history_.add(filter_->state().time_ns,
                        filter_->state().vel_ned_mps - vel_before_ned_mps);
  ++counters_.imu_used;
  if (mode_ == EngineMode::kInitializing || mode_ == EngineMode::kInertialLost) {
    // Back to inertial navigation; aided modes resume with the next measurement.
    mode_ = EngineMode::kInertialOnly;
  }
  if (config_.aiding == AidingMode::kMultiDimensional) {
    const bool gnss = last_fix_ns_ >= 0 && 1e-9 * static_cast<double>(inc.time_ns - last_fix_ns_) <=
                                               config_.mdf.gnss_timeout_s;
    // The filter's own speed is held at zero by the ZUPT the test would end: a recent fix
    // whose ground speed is above the threshold by 3 of its sigmas says the vehicle moves (a
    // car pulling away slowly stayed "at rest" for 2 s, 1.3 m behind, on drive_0708).
    const bool fix_says_moving =
        gnss && last_fix_moving_speed_mps_ > config_.mdf.stationarity.speed_mps;
    const double speed = fix_says_moving ? last_fix_moving_speed_mps_
                                         : filter_->state().vel_ned_mps.head<2>().norm();
    stationarity_->update(inc, speed);
    if (stationarity_->ready()) {
      applyStage(stages_->update(stationarity_->stationary(), gnss, inc.time_ns));
      constraintUpdate();
    }
  }
  if (filter_->state().time_ns >= next_output_ns_) {
    next_output_ns_ = (filter_->state().time_ns / period + 1) * period;
    filter_->settleCovariance();  // the solution's sigmas are of this time
    return true;
  }
  return false;
}

void NavigationEngine::crossGap(std::int64_t start_ns) {
  const std::int64_t from_ns = filter_->state().time_ns;
  const double gap_s = 1e-9 * static_cast<double>(start_ns - from_ns);
  const bool bridged = last_increment_.has_value() && gap_s <= config_.gap.max_bridged_s;
  const double speed_mps = filter_->state().vel_ned_mps.norm();
  if (bridged) {
    for (const ImuIncrement& held : heldIncrements(*last_increment_, from_ns, start_ns))
      filter_->propagate(held);
    ++counters_.gaps_bridged;
  } else {
    filter_->restartAt(start_ns);  // nothing to hold: the solution stands where it was
    askReinitialisation();         // ... and is not trustworthy until a GNSS solution
  }
  const GapVariances v = gapVariances(config_.gap, gap_s, bridged, speed_mps);
  for (int i = 0; i < 3; ++i) {
    filter_->addVariance(layout::kPos.index + i, v.position_m2);
    filter_->addVariance(layout::kVel.index + i, v.velocity_m2ps2);
    filter_->addVariance(layout::kAtt.index + i, v.attitude_rad2);
  }
  status_ |= kStatusImuGap;
  ++counters_.imu_gaps;
  const std::int64_t period = config_.solution_period_ns;
  next_output_ns_ = (start_ns / period + 1) * period;
  next_constraint_ns_ = start_ns;
}

void NavigationEngine::start(const NavState& state, double clock_bias_m, double clock_drift_mps,
                             const StateMatrix& initial_covariance) {
  filter_->setSmoothingLog(config_.smoothing_log);
  velocity_history_.clear();
  filter_->initialize(state, clock_bias_m, clock_drift_mps, config_.tuning, baseMask(),
                      config_.fusion, initial_covariance);
  filter_->modelSecondReceiverClock(config_.fused_receivers > 1);
  clocks_started_ = 1;  // a further receiver's clock starts with its next epoch
  // The GLRs' Phi between epochs: the fault manager's (pseudoranges) and the protection
  // levels' own on fixes.
  filter_->keepTransitionSinceUpdate(config_.aiding == AidingMode::kTightlyCoupled ||
                                     config_.integrity.enabled);
  filter_->trackProcessNoise(config_.adaptive_process_noise.enabled);
  filter_->setProcessNoiseScale(process_noise_.scale());
  integrity_->reset();  // the hypotheses describe the previous run of the filter
  for (int i = 0; i < 6; ++i) {
    if (failed_axes_ & (1u << i)) filter_->setAxisFailed(i < 3, i % 3, true);
  }
  const std::int64_t period = config_.solution_period_ns;
  next_output_ns_ = (state.time_ns / period + 1) * period;
  next_constraint_ns_ = state.time_ns;
}

StateMatrix NavigationEngine::alignedCovariance(const AlignedStart& a) const {
  // Position, velocity and clock with the alignment's sigmas; the sensor biases keep the
  // tuning's. The alignment read those biases as tilt and heading (static_alignment.cpp step
  // 8), so the attitude errors are correlated with them: with phi = S_a b_a + S_g b_g + n and
  // the bias error states e = estimate - truth = -b (the estimates start at 0),
  //   P_phi,phi = S_a Sa S_a^T + S_g Sg S_g^T + N,  P_phi,e_a = -S_a Sa,  P_phi,e_g = -S_g Sg,
  // with Sa, Sg the tuning's bias variances and N the rest of the alignment's own budget
  // (noise; at least 0 per axis).
  StateVector sigma = IntegratedFilter::initialSigma(config_.tuning);
  sigma.segment<3>(kPos.index) = a.pos_sigma_ned_m;
  sigma.segment<3>(kVel.index) = a.vel_sigma_ned_mps;
  if (a.has_clock) {
    sigma[kClockBias.index] = a.clock_bias_sigma_m;
    sigma[kClockDrift.index] = a.clock_drift_sigma_mps;
  }
  StateMatrix P = sigma.array().square().matrix().asDiagonal();
  const Eigen::Matrix3d& S_a = a.sensitivity.d_att_d_accel_bias_b;
  const Eigen::Matrix3d& S_g = a.sensitivity.d_att_d_gyro_bias_b;
  const double var_a = config_.tuning.accel_bias_sigma_mps2 * config_.tuning.accel_bias_sigma_mps2;
  const double var_g = config_.tuning.gyro_bias_sigma_radps * config_.tuning.gyro_bias_sigma_radps;
  const Eigen::Matrix3d from_biases = var_a * S_a * S_a.transpose() + var_g * S_g * S_g.transpose();
  const Eigen::Vector3d rest =
      (a.att_sigma_ned_rad.cwiseAbs2() - from_biases.diagonal()).cwiseMax(0.0);
  P.block<3, 3>(kAtt.index, kAtt.index) = from_biases + Eigen::Matrix3d(rest.asDiagonal());
  P.block<3, 3>(kAtt.index, kAccelBias.index) = -var_a * S_a;
  P.block<3, 3>(kAtt.index, kGyroBias.index) = -var_g * S_g;
  P.block<3, 3>(kAccelBias.index, kAtt.index) = -var_a * S_a.transpose();
  P.block<3, 3>(kGyroBias.index, kAtt.index) = -var_g * S_g.transpose();
  if (a.attitude_source == AttitudeSource::kStarTracker &&
      baseMask()[static_cast<std::size_t>(kStarTrackerBias.index)]) {
    // The start took the tracker's attitude with its bias b: phi = -C_b_n (b + v), and the
    // bias error state starts at -b. The tracker's sigma (the alignment's) holds both, so
    // P_phi,phi = Sb I (C Sb C^T, isotropic) + the rest of the alignment's budget, and
    // P_phi,e_st = C_b_n Sb.
    const double var_st =
        config_.tuning.star_tracker_bias_sigma_rad * config_.tuning.star_tracker_bias_sigma_rad;
    const Eigen::Matrix3d C_b_n = a.state.q_b_to_n.toRotationMatrix();
    const Eigen::Vector3d noise = (a.att_sigma_ned_rad.cwiseAbs2().array() - var_st).max(0.0);
    P.block<3, 3>(kAtt.index, kAtt.index) =
        var_st * Eigen::Matrix3d::Identity() + Eigen::Matrix3d(noise.asDiagonal());
    P.block<3, 3>(kAtt.index, kStarTrackerBias.index) = var_st * C_b_n;
    P.block<3, 3>(kStarTrackerBias.index, kAtt.index) = var_st * C_b_n.transpose();
  }
  return P;
}

void NavigationEngine::startFromAlignment() {
  // The clock from the pseudorange solution when there was one.
  AlignedStart a = aligner_->start();
  // The aligner placed the IMU where the antenna is: move it back along the lever arm.
  const Eigen::Vector3d& lever_b = config_.antenna_lever_arm_b_m;
  a.state.position = earth::offsetNed(a.state.position, -(a.state.q_b_to_n * lever_b));
  a.state.vel_ned_mps -= a.state.q_b_to_n * bodyRate().cross(lever_b);
  double clock_bias_m = config_.initial_clock_bias_m;
  double clock_drift_mps = config_.initial_clock_drift_mps;
  if (a.has_clock) {
    clock_bias_m = a.clock_bias_m;
    clock_drift_mps = a.clock_drift_mps;
  }
  start(a.state, clock_bias_m, clock_drift_mps, alignedCovariance(a));
  mode_ = EngineMode::kInertialOnly;  // aided modes with the next measurement
  const double limit = config_.alignment.course_check_heading_sigma_rad;
  course_check_armed_ = a.attitude_source == AttitudeSource::kGyrocompass && limit > 0.0 &&
                        a.att_sigma_ned_rad.z() > limit;
  gyrocompass_heading_sigma_rad_ = a.att_sigma_ned_rad.z();
}

void NavigationEngine::floorBeforeCourseCheck() {
  filter_->floorEarthRateRemainderVariance();
  // At rest: once moving, accelerations make the heading observable by itself.
  if (filter_->state().vel_ned_mps.head<2>().norm() < config_.alignment.rest.speed_mps)
    filter_->floorGyrocompassHeadingVariance(gyrocompass_heading_sigma_rad_);
}

void NavigationEngine::checkHeadingFromCourse(const Eigen::Vector3d& gnss_vel_ned_mps,
                                              double cross_track_sigma_mps) {
  const StateMatrix& P = filter_->covariance();
  if (std::sqrt(P(kAtt.index + 2, kAtt.index + 2)) <=
      config_.alignment.course_check_heading_sigma_rad) {
    course_check_armed_ = false;  // the filter has found the heading by itself
    return;
  }
  const double min_speed = config_.alignment.course_min_speed_mps;
  const Eigen::Vector3d& v_ins = filter_->state().vel_ned_mps;
  const double speed_mps = gnss_vel_ned_mps.head<2>().norm();
  if (speed_mps < min_speed || v_ins.head<2>().norm() < min_speed) return;
  const double course_rad = std::atan2(gnss_vel_ned_mps.y(), gnss_vel_ned_mps.x());
  const double z_rad = std::remainder(course_rad - std::atan2(v_ins.y(), v_ins.x()), 2.0 * M_PI);
  if (!filter_->correctHeadingFromCourse(z_rad, cross_track_sigma_mps / speed_mps, course_rad,
                                         speed_mps))
    return;
  course_check_armed_ = false;
  ++counters_.course_heading_checks;
}

void NavigationEngine::applyStage(const StageDecision& d) {
  mode_ = stageMode(d.stage);
  if (!d.changed) return;
  ++counters_.stage_switches;
  // Between the fixes of two stages that fuse them came ZUPT or NHC updates that the
  // detector's recursion does not carry: its hypotheses start again with the first fix of
  // such a stage. In between (standing, outages) the levels keep the last fix's fault biases.
  if (config_.integrity.enabled && !integrityOnPseudoranges() &&
      (d.stage == MdfStage::kF2Gnss || d.stage == MdfStage::kF3Recovery))
    integrity_->reset();
  const FilterTuning& t = config_.tuning;
  if (config_.mdf.policy == MdfPolicy::kMultiDimensional) {
    StateMask m = config_.mdf.unestimated == ReducedStates::kNone
                      ? stageMask(MdfStage::kF2Gnss)  // every navigation state
                      : stageMask(d.stage);
    // The stages that fuse fixes estimate their position error too, where it is modelled.
    if ((d.stage == MdfStage::kF2Gnss || d.stage == MdfStage::kF3Recovery) &&
        config_.tuning.fix_position_error_sigma_h_m > 0.0)
      m |= maskOf({kFixPositionError});
    // The stages that estimate every bias estimate the scale factors too, where modelled.
    if (m[static_cast<std::size_t>(kAccelBias.index)])
      m |= baseMask() & maskOf({kAccelScale, kGyroScale});
    // Every stage estimates the mounting misalignment, where modelled (the constraint's rows
    // observe it; the fixes through its correlations).
    m |= baseMask() & maskOf({kMountingMisalignment});
    if (config_.mdf.unestimated != ReducedStates::kDropped)
      filter_->setEstimated(m);
    else
      filter_->setActive(m);
  }
  const StateBlock horizontal_att{kAtt.index, 2};
  const StateBlock heading{kAtt.index + 2, 1};
  // Cases I and II are the paper's comparison: always its resets.
  const bool paper = config_.mdf.reset_form == ResetForm::kPaper ||
                     config_.mdf.policy != MdfPolicy::kMultiDimensional;
  const auto reset = [&](ResetBlock which, const StateBlock& b, double sigma) {
    if (!config_.mdf.reset_blocks[static_cast<std::size_t>(which)]) return;
    if (paper)
      filter_->resetVariances(b, sigma);
    else
      filter_->inflateVariances(b, sigma);
  };
  if (paper && d.reset != CovarianceReset::kNone) filter_->zeroOffDiagonal();  // FS
  switch (d.reset) {
    case CovarianceReset::kNone:
    case CovarianceReset::kFs:
      break;
    case CovarianceReset::kFsA:
      reset(ResetBlock::kLevel, horizontal_att, t.level_sigma_rad);
      reset(ResetBlock::kVelocity, kVel, t.vel_sigma_mps);
      break;
    case CovarianceReset::kAll:  // the comparison case II: everything, whatever the list
      filter_->resetVariances(kAccelBias, t.accel_bias_sigma_mps2);
      filter_->resetVariances(kGyroBias, t.gyro_bias_sigma_radps);
      if (t.accel_scale_sigma > 0.0) filter_->resetVariances(kAccelScale, t.accel_scale_sigma);
      if (t.gyro_scale_sigma > 0.0) filter_->resetVariances(kGyroScale, t.gyro_scale_sigma);
      filter_->resetVariances(kPos, t.pos_sigma_m);
      filter_->resetVariances(kVel, t.vel_sigma_mps);
      filter_->resetVariances(horizontal_att, t.level_sigma_rad);
      filter_->resetVariances(heading, t.heading_sigma_rad);
      break;
    case CovarianceReset::kFsI:
      reset(ResetBlock::kPosition, kPos, t.pos_sigma_m);
      reset(ResetBlock::kVelocity, kVel, t.vel_sigma_mps);
      reset(ResetBlock::kLevel, horizontal_att, t.level_sigma_rad);
      reset(ResetBlock::kHeading, heading, t.heading_sigma_rad);
      break;
  }
}

double NavigationEngine::longitudinalAcceleration() const {
  const NavState& s = filter_->state();
  if (!last_increment_ || !(last_increment_->interval_s > 0.0)) return 0.0;
  // The acceleration over the latest increment, C_b_n f_b + g (Coriolis and transport terms,
  // below 1e-3 m/s^2 at car speeds, left out), along the body's forward axis: signed by the
  // force on the body, so that speeding up in reverse pitches the nose down as braking does.
  const ImuIncrement inc = filter_->imuCorrection().applied(*last_increment_);
  const Eigen::Vector3d f_n = s.q_b_to_n * (inc.delta_vel_b_mps / inc.interval_s);
  const Eigen::Vector3d g_n =
      earth::localEarth(config_.tuning.gravity, s.position, s.vel_ned_mps).g_ned;
  return (f_n + g_n).dot(s.q_b_to_n * Eigen::Vector3d::UnitX());
}

void NavigationEngine::constraintUpdate() {
  const std::int64_t t = filter_->state().time_ns;
  if (t < next_constraint_ns_) return;
  next_constraint_ns_ =
      t + static_cast<std::int64_t>(std::llround(config_.mdf.constraint_period_s * 1e9));
  const MdfStage stage = stages_->stage();
  if (stage == MdfStage::kF1ZeroVelocity) {
    const auto r = filter_->update(
        zeroVelocityMeasurement(filter_->state(), config_.mdf.zupt_sigma_mps *
                                                      noiseSigmaFactor(NoiseStream::kZeroVelocity)),
        AidingKind::kZeroVelocity);
    countGated(r.data(), 3);
    adaptNoise(NoiseStream::kZeroVelocity, r.data(), 3);
    ++counters_.zero_velocity_updates;
  } else if (config_.mdf.policy == MdfPolicy::kMultiDimensional &&
             (stage == MdfStage::kF4Constraint || config_.mdf.nhc_with_gnss)) {
    const double per_accel = config_.mdf.nhc_velocity_pitch_per_accel_rad_per_mps2;
    const double velocity_pitch_b_rad =
        per_accel != 0.0 ? per_accel * longitudinalAcceleration() : 0.0;  // 0: a rigid body
    const Eigen::Vector3d mounting_rad = filter_->mountingMisalignment();
    const auto r = filter_->update(
        nonHolonomicMeasurement(
            filter_->state(),
            config_.mdf.nhc_sigma_mps * noiseSigmaFactor(NoiseStream::kNonHolonomic),
            velocity_pitch_b_rad, filter_->modelsMountingMisalignment() ? &mounting_rad : nullptr),
        AidingKind::kNonHolonomic);
    countGated(r.data(), 2);
    adaptNoise(NoiseStream::kNonHolonomic, r.data(), 2);
    ++counters_.nonholonomic_updates;
  }
}

const char* noiseStreamName(NoiseStream s) {
  switch (s) {
    case NoiseStream::kFixPosition:
      return "fix_position";
    case NoiseStream::kFixVelocity:
      return "fix_velocity";
    case NoiseStream::kPseudorange:
      return "pseudorange";
    case NoiseStream::kPseudorangeRate:
      return "pseudorange_rate";
    case NoiseStream::kZeroVelocity:
      return "zero_velocity";
    case NoiseStream::kNonHolonomic:
      return "non_holonomic";
    case NoiseStream::kStarAttitude:
      return "star_attitude";
  }
  return "unknown";
}

double NavigationEngine::noiseSigmaFactor(NoiseStream s) const {
  return std::sqrt(noise_scales_[static_cast<std::size_t>(s)].scale());
}

void NavigationEngine::adaptNoise(NoiseStream s, const ScalarUpdateResult* rows, int n) {
  NoiseScaleEstimator& e = noise_scales_[static_cast<std::size_t>(s)];
  for (int i = 0; i < n; ++i) e.addRow(rows[i]);
  e.closeEpoch();
}

void NavigationEngine::countGated(const ScalarUpdateResult* results, int n) {
  for (int i = 0; i < n; ++i) counters_.rows_gated += results[i].accepted ? 0 : 1;
}

EngineMode NavigationEngine::aidedMode() const {
  if (failed_axes_ != 0) return EngineMode::kAidedAxisFailed;
  return config_.aiding == AidingMode::kTightlyCoupled ? EngineMode::kTightlyCoupled
                                                       : EngineMode::kLooselyCoupled;
}

bool NavigationEngine::addGnssEpoch(std::int64_t time_ns,
                                    const std::vector<SatelliteObservation>& satellites) {
  // While aligning, any mode's pseudoranges serve the alignment's position.
  if (mode_ == EngineMode::kInertialLost ||
      (!aligning() && (config_.aiding != AidingMode::kTightlyCoupled || !filter_->initialized()))) {
    return false;
  }
  // Excluded measurements stay in the epoch, monitored only (their innovations go to the
  // diagnostics for the readmission test); the diagnostics carry at most 24 satellites.
  used_->clear();
  for (const auto& s : satellites) {
    if (s.receiver >= config_.fused_receivers) continue;  // not a fused receiver's
    if (used_->size() >= static_cast<std::size_t>(kMaxEpochSatellites)) {
      ++counters_.epoch_satellites_dropped;
      continue;
    }
    SatelliteObservation o = s;
    const auto it = excluded_.find(s.sv_id);
    const std::uint8_t mask = it == excluded_.end() ? 0 : it->second;
    o.use_range = (mask & static_cast<std::uint8_t>(SatelliteScope::kRange)) == 0;
    o.use_rate = (mask & static_cast<std::uint8_t>(SatelliteScope::kRate)) == 0;
    used_->push_back(o);
  }
  if (aligning()) {
    // Excluded satellites are not used there either.
    aligner_->addPseudoranges(time_ns, firstReceiverObservations());
    if (aligner_->aligned()) startFromAlignment();
    return false;
  }
  filter_->settleCovariance();  // P_Q and the GLR's Phi are read around the update
  startReceiverClocks();
  const bool any = std::any_of(used_->begin(), used_->end(), [](const SatelliteObservation& o) {
    return o.use_range || o.use_rate;
  });
  if (!any) return false;
  if ((status_ & kStatusReinitialising) != 0) {
    reinitialiseFromPseudoranges(time_ns);
    return false;  // this epoch made the new start: nothing to diagnose
  }
  if (course_check_armed_) floorBeforeCourseCheck();
  if (course_check_armed_ &&
      filter_->state().vel_ned_mps.head<2>().norm() >= config_.alignment.course_min_speed_mps) {
    const PseudorangeFix pf = pseudorangeFix(time_ns, firstReceiverObservations(),
                                             earth::geodeticToEcef(filter_->state().position));
    if (pf.valid) checkHeadingFromCourse(pf.fix.vel_ned_mps, pf.fix.vel_sigma_ned_mps.x());
  }
  const double range_factor = noiseSigmaFactor(NoiseStream::kPseudorange);
  const double rate_factor = noiseSigmaFactor(NoiseStream::kPseudorangeRate);
  for (SatelliteObservation& o : *used_) {
    o.pseudorange_sigma_m *= range_factor;
    o.pseudorange_rate_sigma_mps *= rate_factor;
  }
  // P_Q before the updates (zero when the process noise does not adapt).
  const StateMatrix process_part = filter_->processNoisePart();
  const AntennaArms antennas{AntennaArm{config_.antenna_lever_arm_b_m, bodyRate()},
                             AntennaArm{config_.second_antenna_lever_arm_b_m, bodyRate()}};
  const std::vector<MeasurementReport>& reports = filter_->update(*used_, antennas);
  for (const auto& rep : reports) {
    counters_.rows_gated += rep.fused && !rep.result.accepted ? 1 : 0;
    if (!rep.fused) continue;
    noise_scales_[static_cast<std::size_t>(rep.rate ? NoiseStream::kPseudorangeRate
                                                    : NoiseStream::kPseudorange)]
        .addRow(rep.result);
  }
  noise_scales_[static_cast<std::size_t>(NoiseStream::kPseudorange)].closeEpoch();
  noise_scales_[static_cast<std::size_t>(NoiseStream::kPseudorangeRate)].closeEpoch();
  if (config_.adaptive_process_noise.enabled)
    adaptProcessNoise(time_ns, filter_->lastEpoch(), process_part);
  checkConsistency(time_ns, reports);
  ++counters_.gnss_epochs_fused;
  mode_ = aidedMode();
  if (config_.integrity.enabled) integrity_->onEpoch(time_ns, filter_->lastEpoch());
  return true;
}

const std::vector<SatelliteObservation>& NavigationEngine::firstReceiverObservations() {
  if (config_.fused_receivers <= 1) return *used_;
  first_receiver_->clear();
  for (const SatelliteObservation& o : *used_)
    if (o.receiver == 0) first_receiver_->push_back(o);
  return *first_receiver_;
}

void NavigationEngine::startReceiverClocks() {
  for (int r = 1; r < config_.fused_receivers; ++r) {
    const auto bit = static_cast<std::uint8_t>(1u << r);
    if ((clocks_started_ & bit) != 0) continue;
    // c*b and c*f: the mean of the receiver's range and rate residuals from the filter's
    // position and velocity, with the tuning's initial sigmas (what the position's error adds
    // is far inside them), excluded measurements left out; the epoch that started the clock is
    // not fused.
    const AntennaArm arm{config_.second_antenna_lever_arm_b_m, bodyRate()};
    double bias_m = 0.0, drift_mps = 0.0;
    int ranges = 0, rates = 0;
    for (const SatelliteObservation& o : *used_) {
      if (o.receiver != r) continue;
      const RangePrediction p = predictRange(filter_->state(), 0.0, 0.0, o, arm);
      if (o.use_range) {
        bias_m += o.pseudorange_m - p.pseudorange_m;
        ++ranges;
      }
      if (o.use_rate) {
        drift_mps += o.pseudorange_rate_mps - p.pseudorange_rate_mps;
        ++rates;
      }
    }
    if (ranges == 0 || rates == 0) continue;
    filter_->resetClock(bias_m / ranges, drift_mps / rates, config_.tuning.clock_bias_sigma_m,
                        config_.tuning.clock_drift_sigma_mps, r);
    clocks_started_ |= bit;
    ++counters_.receiver_clocks_started;
    used_->erase(std::remove_if(used_->begin(), used_->end(),
                                [r](const SatelliteObservation& o) { return o.receiver == r; }),
                 used_->end());
  }
}

bool NavigationEngine::holdGnssEpoch(std::int64_t time_ns,
                                     const std::vector<SatelliteObservation>& satellites,
                                     int receiver) {
  if (hasHeldEpoch() && !joinsHeldEpoch(time_ns, receiver)) return false;
  held_.time_ns = time_ns;
  held_.receivers |= static_cast<std::uint8_t>(1u << receiver);
  for (const SatelliteObservation& o : satellites) {
    held_.satellites.push_back(o);
    held_.satellites.back().receiver = receiver;
  }
  return true;
}

bool NavigationEngine::joinsHeldEpoch(std::int64_t time_ns, int receiver) const {
  return receiver >= 0 && receiver < config_.fused_receivers &&
         (!hasHeldEpoch() ||
          (time_ns == held_.time_ns && (held_.receivers & (1u << receiver)) == 0));
}

bool NavigationEngine::heldEpochComplete() const {
  return held_.receivers == (1u << config_.fused_receivers) - 1u;
}

bool NavigationEngine::fuseHeldEpoch() {
  if (!hasHeldEpoch()) return false;
  const bool fused = addGnssEpoch(held_.time_ns, held_.satellites);
  held_.receivers = 0;
  held_.satellites.clear();
  return fused;
}

ProtectionLevels NavigationEngine::protectionLevels() const {
  if (!config_.integrity.enabled || !filter_->initialized()) return {};
  ProtectionLevels pl =
      integrity_->levels(filter_->covariance().block<3, 3>(kPos.index, kPos.index));
  // On fixes the detector is the levels' own (no fault manager watches fixes, and nothing can
  // be excluded): while it declares a fault, the levels do not bound the error.
  if (!integrityOnPseudoranges() && integrity_->detected()) pl.state = IntegrityState::kUnavailable;
  return pl;
}

bool NavigationEngine::integrityOnPseudoranges() const {
  return config_.aiding == AidingMode::kTightlyCoupled;
}

earth::Geodetic NavigationEngine::fixPositionAtStateTime(const GnssFixMeasurement& fix) const {
  // The merge releases a fix after the last increment that ends before it: the state is up to
  // one IMU interval older than the fix (real logs; the simulator's fixes fall on increments).
  // The fix is moved back along its own velocity to the state's time (10 ms at 16 m/s: 16 cm).
  const double dt_s = 1e-9 * static_cast<double>(filter_->state().time_ns - fix.time_ns);
  if (dt_s == 0.0) return fix.position;
  return earth::offsetNed(fix.position, fix.vel_ned_mps * dt_s);
}

Eigen::Vector3d NavigationEngine::fixVelocityAtStateTime(const GnssFixMeasurement& fix) {
  if (fix.velocity_time_offset_ns == 0) return fix.vel_ned_mps;
  Eigen::Vector3d dv_ned_mps;
  if (!velocity_history_.changeSince(fix.time_ns + fix.velocity_time_offset_ns, dv_ned_mps)) {
    ++counters_.fix_velocities_beyond_history;
    return fix.vel_ned_mps;
  }
  return fix.vel_ned_mps + dv_ned_mps;
}

Eigen::Vector3d NavigationEngine::bodyRate() const {
  if (!last_increment_ || !(last_increment_->interval_s > 0.0)) return Eigen::Vector3d::Zero();
  return filter_->imuCorrection().applied(*last_increment_).delta_angle_b_rad /
         last_increment_->interval_s;
}

void NavigationEngine::addGnssFix(const GnssFixMeasurement& fix) {
  if (aligning()) {
    aligner_->addGnssFix(fix);
    if (aligner_->aligned()) startFromAlignment();  // the course: from the next increment on
    return;
  }
  if (!filter_->initialized() || mode_ == EngineMode::kInertialLost) return;
  filter_->settleCovariance();  // the fix's prior and the GLR's Phi are read before its update
  if ((status_ & kStatusReinitialising) != 0 && config_.aiding != AidingMode::kTightlyCoupled &&
      config_.aiding != AidingMode::kInertialOnly) {
    reinitialiseFromFix(fix);
    return;
  }
  if (config_.aiding == AidingMode::kMultiDimensional) {
    last_fix_ns_ = fix.time_ns;
    last_fix_moving_speed_mps_ =
        fix.vel_ned_mps.head<2>().norm() - 3.0 * fix.vel_sigma_ned_mps.head<2>().norm();
    if (!stationarity_->ready()) return;
    // GNSS availability changes the stage at once, so that the first fix after an outage
    // is used by F3 with the FS/I reset already applied.
    applyStage(stages_->update(stationarity_->stationary(), true, fix.time_ns));
    const MdfStage s = stages_->stage();
    if (s != MdfStage::kF2Gnss && s != MdfStage::kF3Recovery) return;  // stationary: ZUPT only
  } else if (config_.aiding != AidingMode::kLooselyCoupled) {
    return;
  }
  if (course_check_armed_) {
    floorBeforeCourseCheck();
    checkHeadingFromCourse(fix.vel_ned_mps, fix.vel_sigma_ned_mps.head<2>().maxCoeff());
  }
  const Eigen::Vector3d& lever_b = config_.antenna_lever_arm_b_m;
  const Eigen::Vector3d pos_sigma_m =
      fix.pos_sigma_ned_m * noiseSigmaFactor(NoiseStream::kFixPosition);
  const Eigen::Vector3d vel_sigma_mps =
      fix.vel_sigma_ned_mps * noiseSigmaFactor(NoiseStream::kFixVelocity);
  const Eigen::Vector3d fix_vel_ned_mps = fixVelocityAtStateTime(fix);
  const VectorMeasurement position = positionMeasurement(
      filter_->state(), fixPositionAtStateTime(fix), pos_sigma_m, lever_b,
      filter_->modelsFixPositionError() ? &filter_->fixPositionError() : nullptr);
  // The protection levels' detector and the adaptive process noise see the epoch as it stood
  // before the updates.
  FixEpochInput epoch;
  StateMatrix prior_P, phi;
  VectorMeasurement velocity_prior;
  const bool whole_epoch = config_.integrity.enabled || config_.adaptive_process_noise.enabled;
  const StateMatrix process_part = filter_->processNoisePart();
  if (whole_epoch) {
    prior_P = filter_->covariance();
    phi = filter_->transitionSinceUpdate();
    velocity_prior =
        velocityMeasurement(filter_->state(), fix_vel_ned_mps, vel_sigma_mps, lever_b, bodyRate());
    epoch = {&position,         &velocity_prior,      &prior_P, &phi,
             filter_->active(), filter_->estimated(), {}};
  }
  const auto p = filter_->update(position, AidingKind::kPosition);
  countGated(p.data(), 3);
  adaptNoise(NoiseStream::kFixPosition, p.data(), 3);
  const auto v = filter_->update(
      velocityMeasurement(filter_->state(), fix_vel_ned_mps, vel_sigma_mps, lever_b, bodyRate()),
      AidingKind::kVelocity);
  countGated(v.data(), 3);
  adaptNoise(NoiseStream::kFixVelocity, v.data(), 3);
  if (whole_epoch) fixEpoch(fix.time_ns, epoch, p, v, process_part);
  std::array<ScalarUpdateResult, 6> rows{};
  std::copy(p.begin(), p.end(), rows.begin());
  std::copy(v.begin(), v.end(), rows.begin() + 3);
  for (int i = 0; i < 3; ++i) {
    counters_.fix_position_nis.add(p[i].innovation, p[i].innovation_var);
    counters_.fix_velocity_nis.add(v[i].innovation, v[i].innovation_var);
  }
  checkConsistency(fix.time_ns, rows.data(), 6);
  if (config_.fix_innovation_log != nullptr) logFixInnovations(p, pos_sigma_m, v, vel_sigma_mps);
  ++counters_.fixes_fused;
  if (config_.aiding == AidingMode::kLooselyCoupled) mode_ = aidedMode();
}

void NavigationEngine::fixEpoch(std::int64_t time_ns, FixEpochInput& epoch,
                                const std::array<ScalarUpdateResult, 3>& p,
                                const std::array<ScalarUpdateResult, 3>& v,
                                const StateMatrix& process_part) {
  for (std::size_t i = 0; i < 3; ++i) {
    epoch.used[i] = p[i].accepted;
    epoch.used[i + 3] = v[i].accepted;
    epoch.test_ratio[i] = p[i].test_ratio;
    epoch.test_ratio[i + 3] = v[i].test_ratio;
  }
  fixEpochDiagnostics(epoch, fix_gain_, *fix_epoch_);
  if (config_.integrity.enabled) integrity_->onEpoch(time_ns, *fix_epoch_);
  if (config_.adaptive_process_noise.enabled) adaptProcessNoise(time_ns, *fix_epoch_, process_part);
}

void NavigationEngine::adaptProcessNoise(std::int64_t time_ns, const EpochDiagnostics& d,
                                         const StateMatrix& process_part) {
  // While the innovations fail the consistency test, what they show is a fault to flag, not
  // noise to adapt to: the scale holds until they pass again.
  if (!trustworthy()) {
    filter_->forgetProcessNoise();
    return;
  }
  for (Eigen::Index i = 0; i < d.h.rows(); ++i) {
    if (!d.used[static_cast<std::size_t>(i)]) continue;
    const double p = (d.h.row(i) * process_part).dot(d.h.row(i));
    process_noise_.addRow({d.innovation[i], d.innovation_cov(i, i), p});
  }
  process_noise_.closeEpoch(time_ns);
  filter_->setProcessNoiseScale(process_noise_.scale());
  filter_->forgetProcessNoise();  // the next epoch's P_Q: from this epoch on
}

void NavigationEngine::logFixInnovations(const std::array<ScalarUpdateResult, 3>& position,
                                         const Eigen::Vector3d& pos_sigma_m,
                                         const std::array<ScalarUpdateResult, 3>& velocity,
                                         const Eigen::Vector3d& vel_sigma_mps) {
  // The updates whiten each row by its R (error_state.hpp, diagonal here): back to metres.
  FixInnovation f;
  f.time_ns = filter_->state().time_ns;
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    f.position_m[i] = position[k].innovation * pos_sigma_m[i];
    f.position_sigma_m[i] = std::sqrt(std::max(position[k].innovation_var, 0.0)) * pos_sigma_m[i];
    f.velocity_mps[i] = velocity[k].innovation * vel_sigma_mps[i];
    f.velocity_sigma_mps[i] =
        std::sqrt(std::max(velocity[k].innovation_var, 0.0)) * vel_sigma_mps[i];
  }
  f.filter_vel_ned_mps = filter_->state().vel_ned_mps;
  f.consistent = !consistency_.inconsistent();
  config_.fix_innovation_log->add(f);
}

void NavigationEngine::addStarAttitude(const StarAttitudeMeasurement& st) {
  if (aligning()) {
    aligner_->addStarAttitude(st);
    if (aligner_->aligned()) startFromAlignment();
    return;
  }
  if (!config_.use_star_tracker || !filter_->initialized() || mode_ == EngineMode::kInertialLost ||
      config_.aiding == AidingMode::kInertialOnly ||
      config_.aiding == AidingMode::kMultiDimensional)
    return;
  const auto a =
      filter_->update(attitudeMeasurement(filter_->state(), st.q_b_to_i,
                                          starTrackerWhiteSigma(st.sigma_b_rad) *
                                              noiseSigmaFactor(NoiseStream::kStarAttitude),
                                          filter_->starTrackerBias()),
                      AidingKind::kAttitude);
  countGated(a.data(), 3);
  adaptNoise(NoiseStream::kStarAttitude, a.data(), 3);
  ++counters_.star_fused;
  mode_ = aidedMode();
}

Eigen::Vector3d NavigationEngine::starTrackerWhiteSigma(const Eigen::Vector3d& sigma_b_rad) const {
  // The message's sigma is the tracker's whole error per sample (bias and noise). Where the
  // bias is a state, R keeps the rest: sigma^2 - sigma_bias^2, at least 1 % of sigma^2 (a
  // tracker reporting less than the configured bias is taken as mostly bias).
  if (!filter_->active()[static_cast<std::size_t>(kStarTrackerBias.index)]) return sigma_b_rad;
  const double var_bias =
      config_.tuning.star_tracker_bias_sigma_rad * config_.tuning.star_tracker_bias_sigma_rad;
  const Eigen::Vector3d var = sigma_b_rad.cwiseAbs2();
  return (var.array() - var_bias).max(0.01 * var.array()).sqrt().matrix();
}

void NavigationEngine::excludeSatellite(int sv_id, SatelliteScope scope) {
  excluded_[sv_id] |= static_cast<std::uint8_t>(scope);
  status_ |= kStatusSatelliteExcluded;
}

void NavigationEngine::readmitSatellite(int sv_id, SatelliteScope scope) {
  auto it = excluded_.find(sv_id);
  if (it != excluded_.end()) {
    it->second &= static_cast<std::uint8_t>(~static_cast<std::uint8_t>(scope));
    if (it->second == 0) excluded_.erase(it);
  }
  if (excluded_.empty()) status_ &= ~static_cast<std::uint32_t>(kStatusSatelliteExcluded);
}

void NavigationEngine::compensateBias(bool accelerometer, int axis, double bias,
                                      double bias_sigma) {
  (accelerometer ? accel_compensation_ : gyro_compensation_)[axis] += bias;
  if (filter_->initialized() && bias_sigma > 0.0) {
    const int state = (accelerometer ? kAccelBias.index : kGyroBias.index) + axis;
    filter_->addVariance(state, bias_sigma * bias_sigma);
  }
  status_ |= kStatusBiasCompensated;
}

void NavigationEngine::compensateReceiverClock(double jump_m, double sigma_m, int receiver) {
  if (receiver < 0 || receiver >= config_.fused_receivers) return;
  if (filter_->initialized()) filter_->shiftClock(jump_m, sigma_m, receiver);
}

void NavigationEngine::failSensorAxis(bool accelerometer, int axis) {
  failed_axes_ |= static_cast<std::uint8_t>(1u << ((accelerometer ? 0 : 3) + axis));
  if (filter_->initialized()) filter_->setAxisFailed(accelerometer, axis, true);
  status_ |= kStatusAxisFailed;
  if (mode_ == EngineMode::kTightlyCoupled || mode_ == EngineMode::kLooselyCoupled)
    mode_ = aidedMode();
}

void NavigationEngine::restoreSensorAxis(bool accelerometer, int axis) {
  failed_axes_ &= static_cast<std::uint8_t>(~(1u << ((accelerometer ? 0 : 3) + axis)));
  if (filter_->initialized()) filter_->setAxisFailed(accelerometer, axis, false);
  if (failed_axes_ == 0) {
    status_ &= ~static_cast<std::uint32_t>(kStatusAxisFailed);
    if (mode_ == EngineMode::kAidedAxisFailed) mode_ = aidedMode();
  }
}

bool NavigationEngine::selectFusion(FusionStructure s) {
  // Federated needs two local filters (GNSS/INS and star tracker/INS); the adaptive R is
  // estimated for the loosely coupled position, velocity and attitude measurements; the
  // multi-dimensional filter switches the dimension of one centralized filter.
  bool ok = false;
  switch (s) {
    case FusionStructure::kCentralized:
      ok = config_.aiding != AidingMode::kInertialOnly;
      break;
    case FusionStructure::kFederated:
      ok = (config_.aiding == AidingMode::kLooselyCoupled ||
            config_.aiding == AidingMode::kTightlyCoupled) &&
           config_.use_star_tracker;
      break;
    case FusionStructure::kAdaptive:
      ok = config_.aiding == AidingMode::kLooselyCoupled;
      break;
  }
  if (!ok) return false;
  config_.fusion = s;
  if (filter_->initialized()) filter_->setStructure(s);
  return true;
}

void NavigationEngine::markInertialLost() {
  if (filter_->initialized()) mode_ = EngineMode::kInertialLost;
}

}  // namespace navbus::core
