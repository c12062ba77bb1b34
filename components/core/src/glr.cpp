#include "navbus/core/glr.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "navbus/core/chi_square.hpp"

namespace navbus::core {

using namespace glr;

namespace {

constexpr int kRangeStep = 0;
constexpr int kRangeRamp = 1;
/// D of a measurement step per unit magnitude: innovations are predicted minus measured, so a
/// measurement reading long by nu lowers them (doc: inputs table).
constexpr double kStepInput = -1.0;
constexpr int kRateStep = 2;

/// Index of a satellite slot's direction in f (three per slot).
constexpr int satColumn(int slot, int direction) {
  return kImuDirections + kSatDirections * slot + direction;
}

/// Column of a slot's propagated signature in mu: the pseudorange step and the rate step. A
/// ramp is not propagated: it is the sum of steps begun at each later epoch, weighted by the
/// epoch spacing (doc: ramps), formed from the step columns of the newer onsets.
constexpr int muColumn(int slot, int direction) {
  return kImuDirections + 2 * slot + (direction == kRateStep ? 1 : 0);
}

/// The bias state a column-j IMU direction steps: accelerometer x y z, gyro x y z.
constexpr int imuState(int j) {
  return j < 3 ? tc17::kAccelBias.index + j : tc17::kGyroBias.index + (j - 3);
}

struct GroupFit {
  double statistic{0.0};  ///< 1/2 f^T R^+ f
  int rank{0};
};

/// l = 1/2 f^T R^+ f of one group of directions (eq. 12), by a Cholesky factorization with
/// diagonal pivoting of R scaled to unit diagonal: at each step the direction with the most
/// information not explained by those already chosen is taken; directions whose remaining
/// share falls below `tolerance` depend on the chosen ones and are dropped (f lies in the range
/// of R, so the statistic over the chosen basis equals f^T R^+ f).
template <int N>
GroupFit fitGroup(const Eigen::Matrix<double, N, N>& R, const Eigen::Matrix<double, N, 1>& f,
                  double tolerance) {
  Eigen::Matrix<double, N, 1> scale;
  for (int i = 0; i < N; ++i) scale[i] = R(i, i) > 0.0 ? 1.0 / std::sqrt(R(i, i)) : 0.0;
  Eigen::Matrix<double, N, N> A = scale.asDiagonal() * R * scale.asDiagonal();
  Eigen::Matrix<double, N, 1> b = scale.cwiseProduct(f);
  std::array<int, N> idx;
  for (int i = 0; i < N; ++i) idx[static_cast<std::size_t>(i)] = i;
  GroupFit out;
  for (int k = 0; k < N; ++k) {
    int best = -1;
    double best_d = tolerance;
    for (int i = k; i < N; ++i) {
      const double d = A(idx[static_cast<std::size_t>(i)], idx[static_cast<std::size_t>(i)]);
      if (d > best_d) {
        best_d = d;
        best = i;
      }
    }
    if (best < 0) break;
    std::swap(idx[static_cast<std::size_t>(k)], idx[static_cast<std::size_t>(best)]);
    const int p = idx[static_cast<std::size_t>(k)];
    const double d = A(p, p);
    out.statistic += 0.5 * b[p] * b[p] / d;
    for (int i = k + 1; i < N; ++i) {
      const int r = idx[static_cast<std::size_t>(i)];
      const double factor = A(r, p) / d;
      b[r] -= factor * b[p];
      for (int j = k + 1; j < N; ++j) {
        const int c = idx[static_cast<std::size_t>(j)];
        A(r, c) -= factor * A(p, c);
      }
    }
    ++out.rank;
  }
  return out;
}

}  // namespace

const char* glrFaultName(GlrFault fault) {
  switch (fault) {
    case GlrFault::kAccelStep:
      return "accelerometer step";
    case GlrFault::kGyroStep:
      return "gyro step";
    case GlrFault::kRangeStep:
      return "pseudorange step";
    case GlrFault::kRangeRamp:
      return "pseudorange ramp";
    case GlrFault::kRateStep:
      return "pseudorange-rate step";
  }
  return "unknown";
}

GlrMonitor::GlrMonitor() : GlrMonitor(GlrConfig{}) {}

GlrMonitor::GlrMonitor(const GlrConfig& config) {
  configure(config);
}

void GlrMonitor::configure(const GlrConfig& config) {
  config_ = config;
  config_.window = std::clamp(config.window, 1, kMaxWindow);
  onsets_.assign(static_cast<std::size_t>(config_.window), Onset{});
  for (Onset& o : onsets_) {
    o.mu.resize(kStates, kMaxPropagated);
    o.f.resize(kMaxDirections);
  }
  scratch_.resize(kStates, kMaxPropagated);
  mu_support_.resize(kStates, kMaxPropagated);
  reset();
}

void GlrMonitor::reset() {
  onset_head_ = 0;
  onset_count_ = 0;
  have_previous_ = false;
  // Quarantine is a decision of the fault manager: it survives a reset of the statistics.
  std::array<int, 33> quarantined{};
  for (int s = 0; s < slots_used_; ++s) {
    const Slot& slot = slots_[static_cast<std::size_t>(s)];
    if (slot.quarantined) quarantined[static_cast<std::size_t>(slot.sv_id)] = 1;
  }
  slots_ = {};
  slots_used_ = 0;
  slot_of_sv_ = {};
  for (int sv = 1; sv <= 32; ++sv) {
    if (quarantined[static_cast<std::size_t>(sv)]) setQuarantined(sv, true);
  }
  result_ = GlrResult{};
}

void GlrMonitor::claimSlot(int slot, int sv_id) {
  slots_[static_cast<std::size_t>(slot)] = Slot{};
  slots_[static_cast<std::size_t>(slot)].sv_id = sv_id;
  slots_[static_cast<std::size_t>(slot)].last_seen = epochs_;
  slot_of_sv_[static_cast<std::size_t>(sv_id)] = slot + 1;
  // A new satellite has no signature yet at any onset.
  for (Onset& o : onsets_) {
    o.mu.middleCols<2>(muColumn(slot, 0)).setZero();
    o.f.segment<kSatDirections>(satColumn(slot, 0)).setZero();
    o.r_sat[static_cast<std::size_t>(slot)].setZero();
  }
}

void GlrMonitor::setQuarantined(int sv_id, bool quarantined) {
  if (sv_id < 1 || sv_id > 32) return;
  int slot = slot_of_sv_[static_cast<std::size_t>(sv_id)] - 1;
  if (slot < 0) {
    if (!quarantined || slots_used_ >= kMaxSatellites) return;
    slot = slots_used_++;
    claimSlot(slot, sv_id);
  }
  slots_[static_cast<std::size_t>(slot)].quarantined = quarantined;
}

bool GlrMonitor::quarantined(int sv_id) const {
  if (sv_id < 1 || sv_id > 32) return false;
  const int slot = slot_of_sv_[static_cast<std::size_t>(sv_id)] - 1;
  return slot >= 0 && slots_[static_cast<std::size_t>(slot)].quarantined;
}

bool GlrMonitor::validate(const GlrEpoch& e) const {
  if (e.rows < 1 || e.rows > kMaxRows || e.innovation.size() != e.rows ||
      e.innovation_cov.rows() != e.rows || e.innovation_cov.cols() != e.rows ||
      e.h.rows() != e.rows || e.k.cols() != e.rows)
    return false;
  for (int r = 0; r < e.rows; ++r) {
    const int sv = e.sv_id[static_cast<std::size_t>(r)];
    if (sv < 1 || sv > 32) return false;
  }
  return e.innovation.allFinite() && e.innovation_cov.allFinite() && e.h.allFinite() &&
         e.k.allFinite() && e.phi.allFinite() && (!have_previous_ || e.time_ns > time_ns_);
}

void GlrMonitor::assignSlots(const GlrEpoch& e) {
  for (int s = 0; s < slots_used_; ++s) {
    Slot& slot = slots_[static_cast<std::size_t>(s)];
    slot.prev_range_row = slot.range_row;
    slot.prev_rate_row = slot.rate_row;
    slot.range_row = slot.rate_row = -1;
  }
  for (int r = 0; r < e.rows; ++r) {
    const int sv = e.sv_id[static_cast<std::size_t>(r)];
    int slot = slot_of_sv_[static_cast<std::size_t>(sv)] - 1;
    if (slot < 0) {
      // A slot whose satellite has not been seen for a whole window carries no signature
      // any more (every onset that saw it has left the window): reuse it.
      for (int s = 0; s < slots_used_ && slot < 0; ++s) {
        const Slot& old = slots_[static_cast<std::size_t>(s)];
        if (!old.quarantined &&
            epochs_ - old.last_seen > static_cast<std::uint64_t>(config_.window))
          slot = s;
      }
      if (slot < 0) {
        if (slots_used_ >= kMaxSatellites) continue;  // cannot happen with <= 24 per epoch
        slot = slots_used_++;
      } else {
        slot_of_sv_[static_cast<std::size_t>(slots_[static_cast<std::size_t>(slot)].sv_id)] = 0;
      }
      claimSlot(slot, sv);
    }
    Slot& s = slots_[static_cast<std::size_t>(slot)];
    s.last_seen = epochs_;
    (e.is_rate[static_cast<std::size_t>(r)] ? s.rate_row : s.range_row) = r;
  }
}

void GlrMonitor::prepareEpoch(const GlrEpoch& e) {
  const int m = e.rows;
  if (have_previous_) {
    // Closed-loop transition from the previous epoch's prior to this one's (doc eq. C3).
    g_.resize(kStates, prev_k_.cols());
    g_.noalias() = e.phi * prev_k_;
    b_ = e.phi;
    b_.noalias() -= g_ * prev_h_;
  }
  prev_time_ns_ = time_ns_;
  time_ns_ = e.time_ns;
  v_inv_.setIdentity(m, m);
  llt_.solveInPlace(v_inv_);
  w_.noalias() = v_inv_ * e.innovation;
  // The statistics see the state only through H: everything below lives on H's support (the
  // states some row measures: position, velocity and clock in tightly coupled mode), which
  // makes S mu an 8 x 8 product instead of 17 x 17.
  support_size_ = 0;
  for (int j = 0; j < kStates; ++j) {
    if (!e.h.col(j).isZero(0.0)) support_[static_cast<std::size_t>(support_size_++)] = j;
  }
  const int k = support_size_;
  h_support_.resize(m, k);
  for (int c = 0; c < k; ++c) h_support_.col(c) = e.h.col(support_[static_cast<std::size_t>(c)]);
  u_.resize(m, k);
  u_.noalias() = v_inv_ * h_support_;
  s_.resize(k, k);
  s_.noalias() = h_support_.transpose() * u_;
  a_.resize(k);
  a_.noalias() = h_support_.transpose() * w_;
}

void GlrMonitor::propagate(Onset& o) {
  // mu_k = Phi_k (mu_{k-1} - K_{k-1} rho_{k-1}) = B mu_{k-1} - G D_{k-1}  (doc eq. C3).
  const int n = propagatedColumns();
  scratch_.leftCols(n).noalias() = b_ * o.mu.leftCols(n);
  o.mu.leftCols(n) = scratch_.leftCols(n);
  const bool range = config_.range_steps || config_.range_ramps;
  for (int s = 0; s < slots_used_; ++s) {
    const Slot& slot = slots_[static_cast<std::size_t>(s)];
    if (slot.prev_range_row >= 0 && range)
      o.mu.col(muColumn(s, kRangeStep)) -= g_.col(slot.prev_range_row) * kStepInput;
    if (slot.prev_rate_row >= 0 && config_.rate_steps)
      o.mu.col(muColumn(s, kRateStep)) -= g_.col(slot.prev_rate_row) * kStepInput;
  }
}

void GlrMonitor::startOnset(const GlrEpoch& e) {
  if (onset_count_ == config_.window) {
    onset_head_ = (onset_head_ + 1) % config_.window;  // the oldest onset leaves the window
    --onset_count_;
  }
  Onset& o = onsets_[static_cast<std::size_t>((onset_head_ + onset_count_) % config_.window)];
  ++onset_count_;
  o.time_ns = e.time_ns;
  o.ramp_start_ns = prev_time_ns_;
  o.mu.setZero();
  o.f.setZero();
  o.r_imu.setZero();
  for (auto& r : o.r_sat) r.setZero();
  if (config_.imu_steps) {
    // A bias step at the start of the interval: the bias error (estimate minus truth) drops by
    // the step, and Phi_k carries it to this epoch (doc eq. C4).
    for (int j = 0; j < kImuDirections; ++j) o.mu.col(j) = -e.phi.col(imuState(j));
  }
}

void GlrMonitor::accumulate(Onset& o, RampSums& ramp) {
  // rho_c = H mu_c + d_c e_{row_c}; f_c += rho_c^T V^-1 eps; R_cd += rho_c^T V^-1 rho_d
  // (eqs. 9-10), with z_c = H^T V^-1 rho_c = S mu_c + d_c U_{row_c}^T, all on H's support.
  const int n = propagatedColumns();
  const int k = support_size_;
  auto ms = mu_support_.topLeftCorner(k, n);
  for (int r = 0; r < k; ++r) ms.row(r) = o.mu.row(support_[static_cast<std::size_t>(r)]).head(n);
  auto z = scratch_.topLeftCorner(k, n);
  z.noalias() = s_ * ms;
  o.f.head<kImuDirections>().noalias() += ms.leftCols<kImuDirections>().transpose() * a_;
  o.r_imu.noalias() += ms.leftCols<kImuDirections>().transpose() * z.leftCols<kImuDirections>();
  // The onset's share of the ramps: a step from this epoch on, weighted by its spacing.
  const double spacing_s = 1e-9 * static_cast<double>(o.time_ns - o.ramp_start_ns);
  for (int s = 0; s < slots_used_; ++s) {
    const Slot& slot = slots_[static_cast<std::size_t>(s)];
    // Directions (range step, ramp, rate step): signature mu, z (on the support), input d, row.
    std::array<SupportVector, kSatDirections> mu, zc;
    std::array<double, kSatDirections> d{};
    const std::array<int, kSatDirections> row{slot.range_row, slot.range_row, slot.rate_row};
    mu[kRangeStep] = ms.col(muColumn(s, kRangeStep));
    mu[kRateStep] = ms.col(muColumn(s, kRateStep));
    zc[kRangeStep] = z.col(muColumn(s, kRangeStep));
    zc[kRateStep] = z.col(muColumn(s, kRateStep));
    if (slot.range_row >= 0) {
      d[kRangeStep] = kStepInput;
      zc[kRangeStep] += d[kRangeStep] * u_.row(slot.range_row).transpose();
    }
    if (slot.rate_row >= 0 && config_.rate_steps) {
      d[kRateStep] = kStepInput;
      zc[kRateStep] += d[kRateStep] * u_.row(slot.rate_row).transpose();
    }
    RampSums::Slot& r = ramp.slots[static_cast<std::size_t>(s)];
    r.mu += spacing_s * mu[kRangeStep];
    r.z += spacing_s * zc[kRangeStep];
    r.d += spacing_s * d[kRangeStep];
    mu[kRangeRamp] = r.mu;
    zc[kRangeRamp] = r.z;
    d[kRangeRamp] = r.d;
    std::array<bool, kSatDirections> on{config_.range_steps, config_.range_ramps,
                                        config_.rate_steps};
    Eigen::Matrix3d& R = o.r_sat[static_cast<std::size_t>(s)];
    for (int i = 0; i < kSatDirections; ++i) {
      const auto ui = static_cast<std::size_t>(i);
      if (!on[ui]) continue;
      o.f[satColumn(s, i)] += mu[ui].dot(a_) + (row[ui] >= 0 ? d[ui] * w_[row[ui]] : 0.0);
      for (int j = 0; j < kSatDirections; ++j) {
        const auto uj = static_cast<std::size_t>(j);
        if (!on[uj]) continue;
        // rho_i^T V^-1 rho_j = mu_i^T z_j + d_i e_ri^T V^-1 (H mu_j + d_j e_rj)
        double v = mu[ui].dot(zc[uj]);
        if (row[ui] >= 0 && d[ui] != 0.0) {
          double t = u_.row(row[ui]).dot(mu[uj]);
          if (row[uj] >= 0) t += d[uj] * v_inv_(row[ui], row[uj]);
          v += d[ui] * t;
        }
        R(i, j) += v;
      }
    }
  }
}

const GlrResult& GlrMonitor::update(const GlrEpoch& e) {
  if (!validate(e)) {
    ++refused_;
    result_ = GlrResult{};
    return result_;
  }
  llt_.compute(e.innovation_cov);  // used again for V^-1 in prepareEpoch
  if (llt_.info() != Eigen::Success) {
    ++refused_;
    result_ = GlrResult{};
    return result_;
  }
  ++epochs_;
  assignSlots(e);
  const bool had_previous = have_previous_;
  prepareEpoch(e);
  if (had_previous) {
    for (int i = 0; i < onset_count_; ++i)
      propagate(onsets_[static_cast<std::size_t>((onset_head_ + i) % config_.window)]);
    startOnset(e);
  }
  // Newest onset first: the ramp of an onset sums the steps of the newer ones.
  ramp_sums_.clear(slots_used_, support_size_);
  for (int age = 0; age < onset_count_; ++age) accumulate(onsetAt(age), ramp_sums_);
  prev_h_ = e.h;
  prev_k_ = e.k;
  have_previous_ = true;
  evaluate();
  return result_;
}

int GlrMonitor::onsetIndex(int age) const {
  const int i = onset_count_ - 1 - std::clamp(age, 0, std::max(onset_count_ - 1, 0));
  return (onset_head_ + i) % config_.window;
}

GlrMonitor::Onset& GlrMonitor::onsetAt(int age) {
  return onsets_[static_cast<std::size_t>(onsetIndex(age))];
}

const GlrMonitor::Onset& GlrMonitor::onset(int age) const {
  return onsets_[static_cast<std::size_t>(onsetIndex(age))];
}

GlrMonitor::DirectionSums GlrMonitor::directionSums(int age, const GlrHypothesis& h) const {
  if (age < 0 || age >= onset_count_) return {};
  const Onset& o = onset(age);
  if (h.isImu()) {
    const int j = (h.fault == GlrFault::kAccelStep ? 0 : 3) + std::clamp(h.axis, 0, 2);
    return {o.f[j], o.r_imu(j, j)};
  }
  if (h.sv_id < 1 || h.sv_id > 32) return {};
  const int slot = slot_of_sv_[static_cast<std::size_t>(h.sv_id)] - 1;
  if (slot < 0) return {};
  const int j = h.fault == GlrFault::kRangeStep   ? kRangeStep
                : h.fault == GlrFault::kRangeRamp ? kRangeRamp
                                                  : kRateStep;
  return {o.f[satColumn(slot, j)], o.r_sat[static_cast<std::size_t>(slot)](j, j)};
}

double GlrMonitor::imuStatistic(int age) const {
  if (age < 0 || age >= onset_count_) return 0.0;
  const Onset& o = onset(age);
  return fitGroup<kImuDirections>(o.r_imu, o.f.head<kImuDirections>(), config_.rank_tolerance)
      .statistic;
}

double GlrMonitor::satelliteStatistic(int age, int sv_id) const {
  if (age < 0 || age >= onset_count_ || sv_id < 1 || sv_id > 32) return 0.0;
  const int slot = slot_of_sv_[static_cast<std::size_t>(sv_id)] - 1;
  if (slot < 0) return 0.0;
  const Onset& o = onset(age);
  const Eigen::Vector3d f = o.f.segment<kSatDirections>(satColumn(slot, 0));
  return fitGroup<kSatDirections>(o.r_sat[static_cast<std::size_t>(slot)], f,
                                  config_.rank_tolerance)
      .statistic;
}

double GlrMonitor::onsetStatistic(const Onset& o) const {
  double l = 0.0;
  if (config_.imu_steps) {
    l = fitGroup<kImuDirections>(o.r_imu, o.f.head<kImuDirections>(), config_.rank_tolerance)
            .statistic;
  }
  for (int s = 0; s < slots_used_; ++s) {
    if (slots_[static_cast<std::size_t>(s)].quarantined) continue;
    const Eigen::Vector3d f = o.f.segment<kSatDirections>(satColumn(s, 0));
    l = std::max(
        l, fitGroup<kSatDirections>(o.r_sat[static_cast<std::size_t>(s)], f, config_.rank_tolerance)
               .statistic);
  }
  return l;
}

void GlrMonitor::evaluate() {
  result_ = GlrResult{};
  result_.valid = true;
  result_.threshold = config_.threshold;
  int best_age = -1;
  double best = 0.0;
  for (int age = 0; age < onset_count_; ++age) {
    const double l = onsetStatistic(onset(age));
    if (best_age < 0 || l > best) {
      best = l;
      best_age = age;
    }
  }
  if (best_age < 0) return;
  isolate(onset(best_age), best_age, result_);
  result_.statistic = best;
  result_.detected = best >= config_.threshold;
}

GlrResult GlrMonitor::isolationAt(int onset_age) const {
  GlrResult r;
  if (onset_age < 0 || onset_age >= onset_count_) return r;
  r.valid = true;
  r.threshold = config_.threshold;
  const Onset& o = onset(onset_age);
  isolate(o, onset_age, r);
  r.statistic = onsetStatistic(o);
  r.detected = r.statistic >= config_.threshold;
  return r;
}

int GlrMonitor::onsetAge(std::int64_t onset_time_ns) const {
  for (int age = 0; age < onset_count_; ++age) {
    if (onset(age).ramp_start_ns == onset_time_ns) return age;
  }
  return -1;
}

void GlrMonitor::isolate(const Onset& o, int onset_age, GlrResult& r) const {
  r.onset_epochs_ago = onset_age;
  r.onset_time_ns = o.ramp_start_ns;
  r.onset_censored = onset_count_ == config_.window && onset_age == onset_count_ - 1;
  // INS against GNSS (seed 000 sec. 3): the group whose statistic is least likely under no
  // fault, given its number of identifiable directions.
  if (config_.imu_steps) {
    const GroupFit g =
        fitGroup<kImuDirections>(o.r_imu, o.f.head<kImuDirections>(), config_.rank_tolerance);
    r.imu_statistic = g.statistic;
    r.imu_rank = g.rank;
    r.imu_significance = chiSquareSignificance(2.0 * g.statistic, g.rank);
  }
  int best_slot = -1;
  for (int s = 0; s < slots_used_; ++s) {
    if (slots_[static_cast<std::size_t>(s)].quarantined) continue;
    const Eigen::Vector3d f = o.f.segment<kSatDirections>(satColumn(s, 0));
    const GroupFit g =
        fitGroup<kSatDirections>(o.r_sat[static_cast<std::size_t>(s)], f, config_.rank_tolerance);
    const double sig = chiSquareSignificance(2.0 * g.statistic, g.rank);
    if (best_slot < 0 || sig > r.satellite_significance) {
      best_slot = s;
      r.satellite_statistic = g.statistic;
      r.satellite_rank = g.rank;
      r.satellite_significance = sig;
    }
  }
  const bool imu =
      config_.imu_steps && (best_slot < 0 || r.imu_significance >= r.satellite_significance);
  r.source = imu ? GlrSourceClass::kImu
                 : (best_slot >= 0 ? GlrSourceClass::kSatellite : GlrSourceClass::kNone);
  // Which direction (eqs. 14-15 with T a unit vector): f* = f_j, R* = R_jj.
  std::array<GlrCandidate, kMaxSatellites + kImuDirections> all{};
  std::array<int, kMaxSatellites + kImuDirections> column{};
  int count = 0;
  auto scalar = [](double f, double rjj, GlrCandidate& c) {
    c.statistic = rjj > 0.0 ? 0.5 * f * f / rjj : 0.0;
    c.magnitude = rjj > 0.0 ? f / rjj : 0.0;
    c.magnitude_sigma = rjj > 0.0 ? 1.0 / std::sqrt(rjj) : INFINITY;
  };
  if (imu) {
    for (int j = 0; j < kImuDirections; ++j) {
      GlrCandidate& c = all[static_cast<std::size_t>(count)];
      c.hypothesis = {j < 3 ? GlrFault::kAccelStep : GlrFault::kGyroStep, j % 3, 0};
      scalar(o.f[j], o.r_imu(j, j), c);
      column[static_cast<std::size_t>(count++)] = j;
    }
  } else {
    // One candidate per satellite: its most likely fault kind.
    for (int s = 0; s < slots_used_; ++s) {
      const Slot& slot = slots_[static_cast<std::size_t>(s)];
      if (slot.quarantined) continue;
      GlrCandidate best;
      for (int j = 0; j < kSatDirections; ++j) {
        GlrCandidate c;
        c.hypothesis = {j == kRangeStep   ? GlrFault::kRangeStep
                        : j == kRangeRamp ? GlrFault::kRangeRamp
                                          : GlrFault::kRateStep,
                        0, slot.sv_id};
        scalar(o.f[satColumn(s, j)], o.r_sat[static_cast<std::size_t>(s)](j, j), c);
        if (c.statistic > best.statistic || j == 0) best = c;
      }
      all[static_cast<std::size_t>(count++)] = best;
    }
  }
  std::array<int, kMaxSatellites + kImuDirections> order{};
  for (int i = 0; i < count; ++i) order[static_cast<std::size_t>(i)] = i;
  std::sort(order.begin(), order.begin() + count, [&](int a, int b) {
    return all[static_cast<std::size_t>(a)].statistic > all[static_cast<std::size_t>(b)].statistic;
  });
  r.candidate_count = std::min(count, static_cast<int>(r.candidates.size()));
  for (int i = 0; i < r.candidate_count; ++i)
    r.candidates[static_cast<std::size_t>(i)] =
        all[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
  if (r.candidate_count < 2) return;
  r.ambiguous = r.candidates[1].statistic >= r.candidates[0].statistic - config_.ambiguity_margin;
  if (!imu) return;
  // The IMU direction whose signature is closest to the best one's: if they are nearly
  // collinear the data cannot tell them apart, whatever their statistics say (a signature
  // from a misplaced onset can favour either).
  auto corr = [&o](int a, int b) {
    const double den = std::sqrt(o.r_imu(a, a) * o.r_imu(b, b));
    return den > 0.0 ? o.r_imu(a, b) / den : 0.0;
  };
  const int best = column[static_cast<std::size_t>(order[0])];
  int twin = -1;
  for (int j = 0; j < kImuDirections; ++j) {
    if (j != best && (twin < 0 || std::abs(corr(best, j)) > std::abs(corr(best, twin)))) twin = j;
  }
  if (std::abs(corr(best, twin)) >= config_.ambiguity_correlation) {
    r.ambiguous = true;
    for (int i = 0; i < count; ++i) {
      if (column[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])] == twin) {
        r.candidates[1] = all[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
      }
    }
  }
  const int second = r.candidates[1].hypothesis.fault == GlrFault::kAccelStep
                         ? r.candidates[1].hypothesis.axis
                         : 3 + r.candidates[1].hypothesis.axis;
  r.correlation = corr(best, second);
}

}  // namespace navbus::core
