#include "navbus/core/filter/integrated_filter.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "navbus/core/filter/information_fusion.hpp"
#include "navbus/core/ins/static_alignment.hpp"
#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/rotation.hpp"
#include "navbus/core/math/sparse_rows.hpp"

namespace navbus::core {

using namespace layout;

namespace {
constexpr std::size_t kGnssLocal = 0;
constexpr std::size_t kStarLocal = 1;
}  // namespace

StateVector IntegratedFilter::initialSigma(const FilterTuning& tuning) {
  StateVector sigma;
  sigma.segment<3>(kPos.index).setConstant(tuning.pos_sigma_m);
  sigma.segment<3>(kVel.index).setConstant(tuning.vel_sigma_mps);
  sigma.segment<3>(kAtt.index) << tuning.level_sigma_rad, tuning.level_sigma_rad,
      tuning.heading_sigma_rad;
  sigma.segment<3>(kAccelBias.index).setConstant(tuning.accel_bias_sigma_mps2);
  sigma.segment<3>(kGyroBias.index).setConstant(tuning.gyro_bias_sigma_radps);
  // Not modelled: inactive states, whose variance only has to keep P invertible.
  sigma.segment<3>(kAccelScale.index)
      .setConstant(tuning.accel_scale_sigma > 0.0 ? tuning.accel_scale_sigma : 1.0);
  sigma.segment<3>(kGyroScale.index)
      .setConstant(tuning.gyro_scale_sigma > 0.0 ? tuning.gyro_scale_sigma : 1.0);
  // Not modelled: inactive states, whose variance only has to keep P invertible.
  // The block is the star tracker's bias or a land vehicle's mounting misalignment.
  double frame_sigma = 1.0;
  if (tuning.star_tracker_bias_sigma_rad > 0.0) frame_sigma = tuning.star_tracker_bias_sigma_rad;
  if (tuning.mounting_misalignment_sigma_rad > 0.0)
    frame_sigma = tuning.mounting_misalignment_sigma_rad;
  sigma.segment<3>(kStarTrackerBias.index).setConstant(frame_sigma);
  // A second receiver's clock (the pseudorange-error block's last states) is started from its
  // first epoch with these sigmas (NavigationEngine): until then it is not measured.
  sigma[kClockBias.index] = tuning.clock_bias_sigma_m;
  sigma[kClockDrift.index] = tuning.clock_drift_sigma_mps;
  sigma.segment<kPseudorangeError.dof>(kPseudorangeError.index)
      .setConstant(tuning.pseudorange_error_sigma_m > 0.0 ? tuning.pseudorange_error_sigma_m : 1.0);
  if (tuning.fix_position_error_sigma_h_m > 0.0 && !(tuning.pseudorange_error_sigma_m > 0.0))
    sigma.segment<3>(kFixPositionError.index) << tuning.fix_position_error_sigma_h_m,
        tuning.fix_position_error_sigma_h_m, tuning.fix_position_error_sigma_v_m;
  return sigma;
}

void IntegratedFilter::initialize(const NavState& state, double clock_bias_m,
                                  double clock_drift_mps, const FilterTuning& tuning,
                                  const StateMask& active, FusionStructure structure) {
  const StateVector sigma = initialSigma(tuning);
  initialize(state, clock_bias_m, clock_drift_mps, tuning, active, structure,
             sigma.array().square().matrix().asDiagonal());
}

void IntegratedFilter::initialize(const NavState& state, double clock_bias_m,
                                  double clock_drift_mps, const FilterTuning& tuning,
                                  const StateMask& active, FusionStructure structure,
                                  const StateMatrix& initial_covariance) {
  pending_.clear();  // what was gathered belongs to the previous run
  tuning_ = tuning;
  ins_ = StrapdownNed(tuning.gravity);
  ins_.initialize(state);
  clock_bias_m_ = {clock_bias_m};  // a further receiver's clock starts with its first epoch
  clock_drift_mps_ = {clock_drift_mps};
  accel_bias_.setZero();
  gyro_bias_.setZero();
  accel_scale_.setZero();
  gyro_scale_.setZero();
  star_tracker_bias_.setZero();
  fix_position_error_ned_m_.setZero();
  modelSecondReceiverClock(false);  // every satellite forgotten; a second clock is set after
  central_.initialize(initial_covariance, active);
  const Eigen::Vector3d floor_pos = Eigen::Vector3d::Constant(tuning.adaptive_floor_position_m);
  windows_[0].configure(tuning.adaptive_window, floor_pos);
  windows_[1].configure(tuning.adaptive_window,
                        Eigen::Vector3d::Constant(tuning.adaptive_floor_velocity_mps));
  windows_[2].configure(tuning.adaptive_window,
                        Eigen::Vector3d::Constant(tuning.adaptive_floor_attitude_rad));
  phi_since_update_t_.setIdentity();
  const SmoothingPending before = smoothing_;
  smoothing_ = SmoothingPending{};  // a new run: nothing smoothed across its start
  smoothing_.last_record_ns = before.last_record_ns;
  smoothing_.records_kept = before.records_kept;
  structure_ = FusionStructure::kCentralized;
  setStructure(structure);
}

void IntegratedFilter::setStructure(FusionStructure s) {
  settleCovariance();
  if (s == FusionStructure::kFederated && structure_ != FusionStructure::kFederated) {
    // The locals start from the current estimate with 1/share of its information each; their
    // fusion gives back the current covariance.
    for (ErrorState& l : local_) {
      l.initialize(central_.P() * tuning_.federated_share, central_.active());
    }
  }
  if (s == FusionStructure::kAdaptive && structure_ != FusionStructure::kAdaptive) {
    for (auto& w : windows_) w.clear();  // statistics of a new run of innovations
  }
  // Federated -> centralized/adaptive: central_ already holds the master covariance.
  structure_ = s;
}

void IntegratedFilter::propagate(const ImuIncrement& raw, bool suspend_filter) {
  if (smoothing_log_ != nullptr) recordForSmoothing();
  const ImuIncrement inc = imuCorrection().applied(raw);
  const double dt = inc.interval_s;
  // F at the state at the start of the interval (first-order hold of the error dynamics).
  const earth::LocalEarth at_state = ins_.earthAtState();
  const ErrorDynamicsBlocks F = errorDynamicsBlocks(ins_.state(), inc.delta_vel_b_mps / dt,
                                                    inc.delta_angle_b_rad / dt, at_state);
  ins_.propagate(inc, at_state);
  for (std::size_t r = 0; r < clock_bias_m_.size(); ++r)
    clock_bias_m_[r] += clock_drift_mps_[r] * dt;
  if (suspend_filter) {
    settleCovariance();            // the increments before this one
    smoothing_.continues = false;  // the covariance stood still: nothing to smooth across
    return;
  }
  decayGaussMarkovEstimates(dt);
  pending_.add(F, dt, processNoise(dt));
  // Per increment with a smoothing log: the smoother's model is the increments' own.
  if (smoothing_log_ != nullptr || pending_.duration_s() + 0.5 * dt >= tuning_.covariance_period_s)
    settleCovariance();
}

StateVector IntegratedFilter::processNoise(double dt) const {
  // Discrete process noise: white specific force / rate noise into velocity / attitude
  // (isotropic, so the body-to-NED rotation drops out), clock random walks (seed 000 eq. 3),
  // bias random walks (a failed axis's own walk replaces its bias's). The Gauss-Markov states'
  // (star-tracker bias, pseudorange and fix errors) come with their decay (settleCovariance).
  // The inertial part (white noises, bias walks) carries the adaptive process-noise scale.
  const double q_scale = process_noise_scale_;
  StateVector q = StateVector::Zero();
  q.segment<3>(kVel.index)
      .setConstant(std::pow(tuning_.accel_noise_mps2_per_sqrthz, 2) * dt * q_scale);
  q.segment<3>(kAtt.index)
      .setConstant(std::pow(tuning_.gyro_noise_radps_per_sqrthz, 2) * dt * q_scale);
  q[kClockBias.index] = std::pow(tuning_.clock_bias_noise_m_per_sqrts, 2) * dt;
  q[kClockDrift.index] = std::pow(tuning_.clock_drift_noise_mps_per_sqrts, 2) * dt;
  if (modelsMountingMisalignment()) {
    // Random constants with a random walk (layout::kMountingMisalignment).
    q.segment<3>(kMountingMisalignment.index)
        .setConstant(std::pow(tuning_.mounting_misalignment_rw_rad_per_sqrts, 2) * dt);
  }
  if (second_clock_) {
    // The second receiver's oscillator: the first's random walks (seed 000 eq. 3).
    q[kSecondClockBias.index] = q[kClockBias.index];
    q[kSecondClockDrift.index] = q[kClockDrift.index];
  }
  for (int a = 0; a < 3; ++a) {
    q[kAccelBias.index + a] = std::pow(axis_failed_[static_cast<std::size_t>(a)]
                                           ? tuning_.failed_accel_bias_rw_mps2_per_sqrts
                                           : tuning_.accel_bias_rw_mps2_per_sqrts,
                                       2) *
                              dt * q_scale;
    q[kGyroBias.index + a] = std::pow(axis_failed_[static_cast<std::size_t>(3 + a)]
                                          ? tuning_.failed_gyro_bias_rw_radps_per_sqrts
                                          : tuning_.gyro_bias_rw_radps_per_sqrts,
                                      2) *
                             dt * q_scale;
  }
  return q;
}

bool IntegratedFilter::modelsStarTrackerBias() const {
  return !modelsMountingMisalignment() &&
         central_.active()[static_cast<std::size_t>(kStarTrackerBias.index)];
}

void IntegratedFilter::decayGaussMarkovEstimates(double dt) {
  // Each estimate is its process's expected value and decays with it; held constant, its
  // error would gain the unmodelled (1 - decay) b_est.
  if (modelsStarTrackerBias())
    star_tracker_bias_ *= std::exp(-dt / tuning_.star_tracker_bias_correlation_time_s);
  if (modelsPseudorangeErrors())
    pseudorange_errors_.decay(std::exp(-dt / tuning_.pseudorange_error_correlation_time_s));
  if (modelsFixPositionError())
    fix_position_error_ned_m_ *= std::exp(-dt / tuning_.fix_position_error_correlation_time_s);
}

void IntegratedFilter::gaussMarkovTransition(double T, StateMatrix& Phi, StateVector& q) const {
  // First-order Gauss-Markov states: decay exp(-T / tau), driving noise that keeps the variance
  // at sigma^2 (exact discretization over the interval T).
  const auto gaussMarkov = [&](int first, int end, double tau_s, const double* sigma) {
    const double decay = std::exp(-T / tau_s);
    for (int i = first; i < end; ++i) {
      Phi(i, i) = decay;
      q[i] = sigma[i - first] * sigma[i - first] * (1.0 - decay * decay);
    }
  };
  if (modelsStarTrackerBias()) {
    const double sigma[3] = {tuning_.star_tracker_bias_sigma_rad,
                             tuning_.star_tracker_bias_sigma_rad,
                             tuning_.star_tracker_bias_sigma_rad};
    gaussMarkov(kStarTrackerBias.index, kStarTrackerBias.end(),
                tuning_.star_tracker_bias_correlation_time_s, sigma);
  }
  if (modelsPseudorangeErrors()) {
    // Each satellite's pseudorange error; a free state stays at the prior (variance sigma^2).
    const int end = kPseudorangeError.index + pseudorange_errors_.slotsInUse();
    for (int i = kPseudorangeError.index; i < end; ++i)
      gaussMarkov(i, i + 1, tuning_.pseudorange_error_correlation_time_s,
                  &tuning_.pseudorange_error_sigma_m);
  }
  if (modelsFixPositionError()) {
    // The fix's position error per NED axis.
    const double sigma[3] = {tuning_.fix_position_error_sigma_h_m,
                             tuning_.fix_position_error_sigma_h_m,
                             tuning_.fix_position_error_sigma_v_m};
    gaussMarkov(kFixPositionError.index, kFixPositionError.end(),
                tuning_.fix_position_error_correlation_time_s, sigma);
  }
}

void IntegratedFilter::settleCovariance() {
  if (pending_.empty()) return;
  StateMatrix Phi = pending_.transition();
  StateVector q = pending_.processNoise();
  gaussMarkovTransition(pending_.duration_s(), Phi, q);
  if (!second_clock_)
    Phi(kSecondClockBias.index, kSecondClockDrift.index) = 0.0;  // pseudorange-error states
  pending_.clear();
  if (structure_ == FusionStructure::kFederated) {
    for (ErrorState& l : local_) l.predict(Phi, q * tuning_.federated_share);
  }
  // The master (federated) covariance is propagated too, so that it is valid between updates.
  central_.predict(Phi, q);
  if (keep_transition_ || smoothing_log_ != nullptr) {
    const SparseRows<layout::kSize> sparse(Phi, transitionPattern());
    if (keep_transition_)
      phi_since_update_t_ =
          sparse.timesTransposedBlockTriangular<kCoupledSize>(phi_since_update_t_);
    if (smoothing_log_ != nullptr)
      smoothing_.transition_t =
          sparse.timesTransposedBlockTriangular<kCoupledSize>(smoothing_.transition_t);
  }
  if (smoothing_log_ != nullptr) {
    // P(k|k-1) as the propagation made it; a covariance jump before the updates replaces it
    // with P after the jump (endCovarianceJump).
    smoothing_.predicted = central_.P();
    smoothing_.predicted_taken = true;
  }
}

void IntegratedFilter::recordForSmoothing() {
  const std::int64_t now_ns = ins_.state().time_ns;
  if (smoothing_.updated || smoothing_.starts_run ||
      now_ns - smoothing_.last_record_ns >= smoothing_log_->interval())
    emitSmoothingRecord();
}

void IntegratedFilter::closeSmoothingRecord() {
  settleCovariance();
  if (smoothing_log_ != nullptr && initialized() &&
      (smoothing_.updated || ins_.state().time_ns > smoothing_.last_record_ns))
    emitSmoothingRecord();
}

void IntegratedFilter::emitSmoothingRecord() {
  SmoothingRecord r;
  r.time_ns = ins_.state().time_ns;
  r.state = ins_.state();
  r.accel_bias_mps2 = accel_bias_;
  r.gyro_bias_radps = gyro_bias_;
  r.covariance = central_.P();
  r.predicted = smoothing_.predicted_taken ? smoothing_.predicted : central_.P();
  r.transition = smoothing_.transition_t.transpose();
  r.correction = smoothing_.correction;
  r.active = central_.active();
  r.continues = smoothing_.continues;
  smoothing_log_->add(r, smoothing_.records_kept);
  smoothing_ = SmoothingPending{};
  smoothing_.continues = true;
  smoothing_.starts_run = false;
  smoothing_.last_record_ns = r.time_ns;
  smoothing_.records_kept = static_cast<std::int64_t>(smoothing_log_->records().size());
}

void IntegratedFilter::trackProcessNoise(bool on) {
  settleCovariance();
  central_.trackProcessNoise(on ? maskOf({kVel, kAtt, kAccelBias, kGyroBias}) : StateMask());
}

void IntegratedFilter::beginCovarianceJump() {
  settleCovariance();
  // The updates already taken at this epoch stay before the jump: their record first.
  if (smoothing_log_ != nullptr && smoothing_.updated) emitSmoothingRecord();
}

void IntegratedFilter::endCovarianceJump(int replaced_state) {
  if (smoothing_log_ == nullptr) return;
  // Nothing changed P since the propagation or the last record but the jump: the prior of the
  // next updates (or the next propagation's start) is P as it now is.
  if (replaced_state >= 0) smoothing_.transition_t.col(replaced_state).setZero();
  smoothing_.predicted = central_.P();
  smoothing_.predicted_taken = true;
}

void IntegratedFilter::breakSmoothing() {
  beginCovarianceJump();
  smoothing_.continues = false;
}

ErrorState& IntegratedFilter::target(AidingKind kind) {
  if (structure_ != FusionStructure::kFederated) return central_;
  return kind == AidingKind::kAttitude ? local_[kStarLocal] : local_[kGnssLocal];
}

InnovationWindow<3>* IntegratedFilter::window(AidingKind kind) {
  if (structure_ != FusionStructure::kAdaptive) return nullptr;
  switch (kind) {
    case AidingKind::kPosition:
      return &windows_[0];
    case AidingKind::kVelocity:
      return &windows_[1];
    case AidingKind::kAttitude:
      return &windows_[2];
    default:
      return nullptr;
  }
}

const std::vector<MeasurementReport>& IntegratedFilter::update(
    const std::vector<SatelliteObservation>& sats, const AntennaArm& antenna) {
  AntennaArms antennas;
  antennas.fill(antenna);
  return update(sats, antennas);
}

const std::vector<MeasurementReport>& IntegratedFilter::update(
    const std::vector<SatelliteObservation>& sats, const AntennaArms& antennas) {
  settleCovariance();
  ErrorState& es = structure_ == FusionStructure::kFederated ? local_[kGnssLocal] : central_;
  const auto m = static_cast<Eigen::Index>(2 * sats.size());
  EpochDiagnostics& d = *last_epoch_;
  d.sv_ids.clear();
  d.is_rate.clear();
  d.receivers.clear();
  d.used.clear();
  d.test_ratio.clear();
  d.innovation.resize(m);
  d.h.resize(m, kSize);
  Eigen::VectorXd& r = *range_variances_;
  r.resize(m);
  const std::vector<int>& error_state = pseudorangeErrorStates(sats);
  for (std::size_t i = 0; i < sats.size(); ++i) {
    const auto& sat = sats[i];
    const std::size_t rx = slot(sat.receiver);
    const RangePrediction p =
        predictRange(ins_.state(), clock_bias_m_[rx], clock_drift_mps_[rx], sat, antennas[rx]);
    const auto row = static_cast<Eigen::Index>(2 * i);
    // Innovations in the error-state form z = H dx + v: predicted minus measured (seed 000 eq. 5).
    d.innovation[row] = p.pseudorange_m - sat.pseudorange_m;
    d.innovation[row + 1] = p.pseudorange_rate_mps - sat.pseudorange_rate_mps;
    d.h.row(row) = p.h_range;
    d.h.row(row + 1) = p.h_rate;
    if (error_state[i] >= 0) {
      // The predicted pseudorange includes the satellite's estimated error; its error (estimate
      // minus truth) enters the innovation with +1.
      d.innovation[row] += pseudorange_errors_.estimate(error_state[i]);
      d.h(row, error_state[i]) = 1.0;
    }
    r[row] = sat.pseudorange_sigma_m * sat.pseudorange_sigma_m;
    r[row + 1] = sat.pseudorange_rate_sigma_mps * sat.pseudorange_rate_sigma_mps;
    d.sv_ids.insert(d.sv_ids.end(), {sat.sv_id, sat.sv_id});
    d.is_rate.insert(d.is_rate.end(), {false, true});
    d.receivers.insert(d.receivers.end(), {sat.receiver, sat.receiver});
  }
  // Batch view from the prior covariance, published for the GLR; the update itself is
  // sequential (exact for the diagonal R) so that each row can be gated on its own.
  applied_gain_->prepare(d, es.P());
  d.innovation_cov.diagonal() += r;
  d.phi = phi_since_update_t_.transpose();
  std::vector<MeasurementReport>& reports = *reports_;
  reports.clear();
  for (Eigen::Index row = 0; row < m; ++row) {
    ScalarUpdateResult res;
    const SatelliteObservation& sat = sats[static_cast<std::size_t>(row / 2)];
    const bool fuse = row % 2 == 0 ? sat.use_range : sat.use_rate;
    if (fuse) {
      AidingMeasurement<1> one;
      one.z[0] = d.innovation[row];
      one.h = d.h.row(row);
      one.r(0, 0) = r[row];
      res = es.update(one, tuning_.gate_sigma)[0];
    } else {
      // Monitored only: the innovation test of the row, no update.
      res.innovation = d.innovation[row];
      res.innovation_var = d.innovation_cov(row, row);
      const double gate = tuning_.gate_sigma > 0.0 ? tuning_.gate_sigma : 1.0;
      res.test_ratio = res.innovation * res.innovation / (gate * gate * res.innovation_var);
    }
    d.test_ratio.push_back(res.test_ratio);
    d.used.push_back(res.accepted);
    reports.push_back({d.sv_ids[static_cast<std::size_t>(row)],
                       d.is_rate[static_cast<std::size_t>(row)], fuse, res});
  }
  if (!applied_gain_->computeFromPosterior(d, es.P(), r, es.estimated())) applied_gain_->compute(d);
  closeUpdate();
  return reports;
}

bool IntegratedFilter::modelsFixPositionError() const {
  return central_.active()[static_cast<std::size_t>(kFixPositionError.index)] &&
         tuning_.fix_position_error_sigma_h_m > 0.0 && !(tuning_.pseudorange_error_sigma_m > 0.0);
}

bool IntegratedFilter::modelsMountingMisalignment() const {
  return central_.active()[static_cast<std::size_t>(kMountingMisalignment.index)] &&
         tuning_.mounting_misalignment_sigma_rad > 0.0;
}

bool IntegratedFilter::modelsPseudorangeErrors() const {
  return central_.active()[static_cast<std::size_t>(kPseudorangeError.index)] &&
         tuning_.pseudorange_error_sigma_m > 0.0;
}

const std::vector<int>& IntegratedFilter::pseudorangeErrorStates(
    const std::vector<SatelliteObservation>& sats) {
  if (!modelsPseudorangeErrors()) {
    no_error_states_->assign(sats.size(), -1);
    return *no_error_states_;
  }
  std::vector<int>& sv_ids = *epoch_sv_ids_;
  sv_ids.clear();
  for (const SatelliteObservation& sat : sats) sv_ids.push_back(sat.sv_id);
  const PseudorangeErrorSlots::Assignment& a = pseudorange_errors_.assign(sv_ids);
  for (const int i : a.fresh) resetState(i, tuning_.pseudorange_error_sigma_m);
  return a.state_index;
}

void IntegratedFilter::closeUpdate() {
  if (structure_ == FusionStructure::kFederated) {
    // Master fusion (eqs. 28-29) of the shared states; the clock comes from the GNSS local.
    const FusedEstimate<kFusedStates> f =
        fuseInformation<kFusedStates>(local_[kGnssLocal], local_[kStarLocal]);
    StateVector dx = StateVector::Zero();
    dx.head<kFusedStates>() = f.x;
    dx.tail<kSize - kFusedStates>() = local_[kGnssLocal].x().tail<kSize - kFusedStates>();
    StateMatrix P = StateMatrix::Zero();
    P.topLeftCorner<kFusedStates, kFusedStates>() = f.P;
    P.bottomRightCorner<kSize - kFusedStates, kSize - kFusedStates>() =
        local_[kGnssLocal].P().bottomRightCorner<kSize - kFusedStates, kSize - kFusedStates>();
    central_.initialize(P, central_.active());
    // No-reset mode: the locals keep their covariances; their estimates are now relative to
    // the corrected mechanization.
    for (ErrorState& l : local_) l.shift(dx);
    feedback(dx);
  } else {
    turnAttitudeCovariance(central_.x()[kAtt.index + 2]);
    feedback(central_.x());
    central_.x().setZero();
  }
  phi_since_update_t_.setIdentity();
}

void IntegratedFilter::turnAttitudeCovariance(double dpsi_rad) {
  // The reset of the tilt errors under a heading correction. The levelling left the computed
  // horizontal specific force at 0, -(phi x f^n)_h = (C_est e_a)_h with f^n = (0, 0, -g): the
  // tilts and the horizontal accelerometer-bias errors are correlated through the frame the INS
  // computed. The feedback turns that frame about the vertical, C_new = R_D(dpsi) C_est, and the
  // computed specific force with it, which keeps it vertical: the relation holds with C_new,
  // so the true tilts after the correction are R_D(dpsi) times those before. The linear update
  // keeps them as they were, wrong by [dpsi x] phi: a second order, but P holds the levelled
  // combination far more tightly than its parts, and a 28 mrad correction (3 sigma of a
  // 0.1 deg/h gyrocompass, taken while the vehicle accelerates) turns 2.8 % of each tilt into
  // the other. So the attitude rows and columns of P turn by R_D(dpsi), the Jacobian of this
  // reset. A tilt correction keeps the computed force vertical only to first order, with no
  // heading term: nothing to turn (turning by it too mixes the heading's variance, up to a
  // gyrocompass's 83 mrad, into the levelled tilts; measured: seed 000 NEES 10 -> 32).
  const Eigen::Matrix3d R_D =
      Eigen::AngleAxisd(dpsi_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  StateMatrix& P = central_.P();
  P.middleRows<3>(kAtt.index) = (R_D * P.middleRows<3>(kAtt.index)).eval();
  P.middleCols<3>(kAtt.index) = (P.middleCols<3>(kAtt.index) * R_D.transpose()).eval();
  central_.turnProcessNoise(kAtt, R_D);
}

void IntegratedFilter::feedback(const StateVector& dx) {
  if (smoothing_log_ != nullptr) {
    smoothing_.correction += dx;
    smoothing_.updated = true;
  }
  // Errors are estimate minus truth: subtract them from the estimate, then the error state is 0.
  ins_.correct(correctedState(ins_.state(), dx));
  accel_bias_ -= dx.segment<3>(kAccelBias.index);
  gyro_bias_ -= dx.segment<3>(kGyroBias.index);
  accel_scale_ -= dx.segment<3>(kAccelScale.index);
  gyro_scale_ -= dx.segment<3>(kGyroScale.index);
  star_tracker_bias_ -= dx.segment<3>(kStarTrackerBias.index);  // or the mounting's (same block)
  for (int r = 0; r < (second_clock_ ? 2 : 1); ++r) {
    clock_bias_m_[slot(r)] -= dx[clockBiasOf(r).index];
    clock_drift_mps_[slot(r)] -= dx[clockDriftOf(r).index];
  }
  if (modelsFixPositionError()) {
    fix_position_error_ned_m_ -= dx.segment<3>(kFixPositionError.index);
  } else {
    pseudorange_errors_.correct(dx.segment<kPseudorangeError.dof>(kPseudorangeError.index));
  }
}

void IntegratedFilter::setActive(const StateMask& active) {
  settleCovariance();
  central_.setActive(active);
  for (ErrorState& l : local_) l.setActive(active);
}

void IntegratedFilter::setEstimated(const StateMask& estimated) {
  settleCovariance();
  central_.setEstimated(estimated);
  for (ErrorState& l : local_) l.setEstimated(estimated);
}

void IntegratedFilter::zeroOffDiagonal() {
  settleCovariance();
  breakSmoothing();  // no process noise gives it
  central_.zeroOffDiagonal();
  for (ErrorState& l : local_) l.zeroOffDiagonal();
}

void IntegratedFilter::setAxisFailed(bool accelerometer, int axis, bool failed) {
  settleCovariance();
  bool& flag = axis_failed_[static_cast<std::size_t>((accelerometer ? 0 : 3) + axis)];
  if (failed && !flag) {
    const double sigma =
        accelerometer ? tuning_.failed_accel_bias_sigma_mps2 : tuning_.failed_gyro_bias_sigma_radps;
    addVariance((accelerometer ? kAccelBias.index : kGyroBias.index) + axis, sigma * sigma);
  }
  flag = failed;
}

void IntegratedFilter::addVariance(int state, double variance) {
  beginCovarianceJump();  // process noise of the smoother's model
  central_.P()(state, state) += variance;
  for (ErrorState& l : local_) l.P()(state, state) += variance * tuning_.federated_share;
  endCovarianceJump();
}

bool IntegratedFilter::correctHeadingFromCourse(double z_rad, double sigma_rad, double course_rad,
                                                double speed_mps) {
  settleCovariance();
  if (structure_ == FusionStructure::kFederated || speed_mps <= 0.0) return false;
  constexpr int kHeading = kAtt.index + 2;
  // z observes the cross-track velocity error; the heading follows through its correlation
  // with it (the velocity gained through the heading error).
  StateVector h = StateVector::Zero();
  h[kVel.index] = std::sin(course_rad) / speed_mps;  // -u_c / speed, u_c = (-sin c, cos c, 0)
  h[kVel.index + 1] = -std::cos(course_rad) / speed_mps;
  StateMatrix& P = central_.P();
  const StateVector Ph = P * h;
  const StateVector k = Ph / (h.dot(Ph) + sigma_rad * sigma_rad);
  P -= k * Ph.transpose();
  P = (0.5 * (P + P.transpose())).eval();
  central_.carryProcessNoise(h.transpose(), k);
  StateVector dx = k * z_rad;
  // The horizontal velocity turns with the heading: v - dx_v = R_D(dx_psi) v.
  const double a = dx[kHeading];
  const Eigen::Vector3d& v = ins_.state().vel_ned_mps;
  dx[kVel.index] = v.x() - (std::cos(a) * v.x() - std::sin(a) * v.y());
  dx[kVel.index + 1] = v.y() - (std::sin(a) * v.x() + std::cos(a) * v.y());
  // The gyro biases learned under the heading error took the Earth rate's mismatch whole; the
  // linear gain removed its first order only: add the rest (the sigma_psi term: its spread).
  const Eigen::Matrix3d C_n_b = ins_.state().q_b_to_n.conjugate().toRotationMatrix();
  const Eigen::Vector3d w_ie_n = earth::omegaIeNed(ins_.state().position.latitude_rad);
  const EarthRateMismatch m = earthRateMismatchRemainder(a, w_ie_n);
  dx.segment<3>(kGyroBias.index) += C_n_b * m.remainder_radps;
  const Eigen::Vector3d spread_b = C_n_b * m.d_remainder_d_psi * std::sqrt(P(kHeading, kHeading));
  P.block<3, 3>(kGyroBias.index, kGyroBias.index) += spread_b * spread_b.transpose();
  turnAttitudeCovariance(dx[kHeading]);
  feedback(dx);
  return true;
}

void IntegratedFilter::floorEarthRateRemainderVariance() {
  settleCovariance();
  // The federated master is rebuilt from its locals at every update (and takes no course check).
  if (structure_ == FusionStructure::kFederated) return;
  StateMatrix& P = central_.P();
  const double required = earthRateRemainderNorthVariance(
      P(kAtt.index + 2, kAtt.index + 2), earth::omegaIeNed(ins_.state().position.latitude_rad));
  // The computed north axis in the body frame.
  const Eigen::Vector3d u_b = ins_.state().q_b_to_n.conjugate() * Eigen::Vector3d::UnitX();
  const double now = u_b.dot(P.block<3, 3>(kGyroBias.index, kGyroBias.index) * u_b);
  if (now >= required) return;
  beginCovarianceJump();
  P.block<3, 3>(kGyroBias.index, kGyroBias.index) += (required - now) * u_b * u_b.transpose();
  endCovarianceJump();
}

void IntegratedFilter::floorGyrocompassHeadingVariance(double heading_sigma_rad) {
  settleCovariance();
  if (structure_ == FusionStructure::kFederated) return;
  // At rest the heading and the east gyro bias are one observable (static_alignment.cpp step
  // 8: phi_D = -e_g^n_E / (W cos L) with the bias error e = -b), which gyrocompassing has read.
  // Along the direction that moves both and keeps that combination, d = (phi_D 1, e_g^n_E
  // -W cos L), the data hold nothing more; the filter's first-order model learns there from the
  // second-order terms of a heading error this large (the heading sigma fell from 83 to 58 mrad
  // in 440 s at rest, the error did not). Its variance stays the gyrocompass's.
  StateMatrix& P = central_.P();
  const int heading = kAtt.index + 2;
  if (P(heading, heading) >= heading_sigma_rad * heading_sigma_rad) return;
  const double w_h = earth::omegaIeNed(ins_.state().position.latitude_rad).x();
  StateVector d = StateVector::Zero();
  d[heading] = 1.0;
  d.segment<3>(kGyroBias.index) =
      ins_.state().q_b_to_n.conjugate() * Eigen::Vector3d(0.0, -w_h, 0.0);
  beginCovarianceJump();
  P += (heading_sigma_rad * heading_sigma_rad - P(heading, heading)) * d * d.transpose();
  endCovarianceJump();
}

void IntegratedFilter::inflateVariances(const StateBlock& block, double sigma) {
  settleCovariance();
  for (int i = block.index; i < block.end(); ++i) {
    const double v = central_.P()(i, i);
    if (v < sigma * sigma) addVariance(i, sigma * sigma - v);
  }
}

void IntegratedFilter::resetNavigation(const GnssFixMeasurement& fix) {
  settleCovariance();
  breakSmoothing();  // what the filter knew of position and velocity is dropped
  NavState s = ins_.state();
  s.position = fix.position;
  s.vel_ned_mps = fix.vel_ned_mps;
  ins_.correct(s);
  for (int i = 0; i < 3; ++i) {
    resetState(layout::kPos.index + i, fix.pos_sigma_ned_m[i]);
    resetState(layout::kVel.index + i, fix.vel_sigma_ned_mps[i]);
  }
}

void IntegratedFilter::resetClock(double bias_m, double drift_mps, double bias_sigma_m,
                                  double drift_sigma_mps, int receiver) {
  settleCovariance();
  clock_bias_m_[slot(receiver)] = bias_m;
  clock_drift_mps_[slot(receiver)] = drift_mps;
  resetState(layout::clockBiasOf(receiver).index, bias_sigma_m);
  resetState(layout::clockDriftOf(receiver).index, drift_sigma_mps);
}

void IntegratedFilter::modelSecondReceiverClock(bool on) {
  settleCovariance();
  second_clock_ = on;
  pseudorange_errors_.leaveStatesToSecondClock(on);
}

void IntegratedFilter::shiftClock(double jump_m, double sigma_m, int receiver) {
  settleCovariance();
  clock_bias_m_[slot(receiver)] += jump_m;
  if (sigma_m > 0.0) addVariance(layout::clockBiasOf(receiver).index, sigma_m * sigma_m);
}

void IntegratedFilter::resetState(int i, double sigma) {
  beginCovarianceJump();  // a fresh state: a zero row of Phi and the prior as process noise
  central_.resetState(i, sigma);
  for (ErrorState& l : local_) {  // a local filter that does not carry the state keeps 0
    if (l.P()(i, i) > 0.0) l.resetState(i, sigma * std::sqrt(tuning_.federated_share));
  }
  endCovarianceJump(i);
}

void IntegratedFilter::resetVariances(const StateBlock& block, double sigma) {
  settleCovariance();
  breakSmoothing();  // variances set, correlations kept: no process noise gives it
  central_.setVariances(block, sigma);
  for (ErrorState& l : local_) l.setVariances(block, sigma * std::sqrt(tuning_.federated_share));
}

}  // namespace navbus::core
