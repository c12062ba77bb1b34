#include "navbus/core/integrity/glr.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "navbus/core/math/chi_square.hpp"

namespace navbus::core {

using namespace glr;

namespace {

constexpr int kRangeStep = 0;
constexpr int kRangeRamp = 1;
/// D of a measurement step per unit magnitude: innovations are predicted minus measured, so a
/// measurement reading long by nu lowers them (doc: inputs table).
constexpr double kStepInput = -1.0;
constexpr int kRateStep = 2;

/// The sensor error states between attitude and clock: accelerometer, gyro and star-tracker
/// biases and the IMU's scale factors (random constants, or inactive states, in the filters the
/// GLR watches).
constexpr int kBiasIndex = layout::kAccelBias.index;
constexpr int kBiasStates = kSupportTail.index - kBiasIndex;
static_assert(layout::kGyroBias.index == layout::kAccelBias.end() &&
              layout::kAtt.end() == kBiasIndex &&
              layout::kStarTrackerBias.index == layout::kGyroBias.end() &&
              layout::kAccelScale.index == layout::kStarTrackerBias.end() &&
              layout::kGyroScale.index == layout::kAccelScale.end() &&
              layout::kGyroScale.end() == kSupportTail.index);

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
  return j < 3 ? layout::kAccelBias.index + j : layout::kGyroBias.index + (j - 3);
}

struct GroupFit {
  double statistic{0.0};  ///< 1/2 f^T R^+ f
  int rank{0};
};

/// The same statistic without pivoting, when no direction can be dropped: scaled to unit
/// diagonal (A), each direction's smallest unexplained share is det(A) / cofactor_ii(A) >=
/// det(A) (a principal minor of a unit-diagonal correlation matrix is at most 1), so
/// det(A) = prod(LDL^T pivots) / prod(R_ii) > tolerance means full rank, and the order of
/// elimination does not change f^T R^-1 f. Returns false when that cannot be shown.
template <int N>
bool fitFullRank(const Eigen::Matrix<double, N, N>& R, const Eigen::Matrix<double, N, 1>& f,
                 double tolerance, GroupFit& out) {
  Eigen::Matrix<double, N, N> A = R;
  Eigen::Matrix<double, N, 1> b = f;
  double det_ratio = 1.0;
  out = GroupFit{};
  for (int k = 0; k < N; ++k) {
    const double d = A(k, k);
    if (!(d > 0.0) || !(R(k, k) > 0.0)) return false;
    det_ratio *= d / R(k, k);
    out.statistic += 0.5 * b[k] * b[k] / d;
    for (int i = k + 1; i < N; ++i) {
      const double factor = A(i, k) / d;
      b[i] -= factor * b[k];
      for (int j = k + 1; j <= i; ++j) A(i, j) -= factor * A(j, k);
    }
  }
  out.rank = N;
  return det_ratio > tolerance;
}

/// l = 1/2 f^T R^+ f of one group of directions (eq. 12), by a Cholesky factorization with
/// diagonal pivoting of R scaled to unit diagonal: at each step the direction with the most
/// information not explained by those already chosen is taken; directions whose remaining
/// share falls below `tolerance` depend on the chosen ones and are dropped (f lies in the range
/// of R, so the statistic over the chosen basis equals f^T R^+ f).
/// fitFullRank first: most groups are well conditioned.
template <int N>
GroupFit fitGroup(const Eigen::Matrix<double, N, N>& R, const Eigen::Matrix<double, N, 1>& f,
                  double tolerance) {
  GroupFit fast;
  if (fitFullRank<N>(R, f, tolerance, fast)) return fast;
  Eigen::Matrix<double, N, 1> scale;
  for (int i = 0; i < N; ++i) scale[i] = R(i, i) > 0.0 ? 1.0 / std::sqrt(R(i, i)) : 0.0;
  Eigen::Matrix<double, N, N> A = scale.asDiagonal() * R * scale.asDiagonal();
  Eigen::Matrix<double, N, 1> b = scale.cwiseProduct(f);
  GroupFit out;
  for (int k = 0; k < N; ++k) {
    // Pivot: the remaining direction with the largest unexplained share, moved to position k.
    int best = -1;
    double best_d = tolerance;
    for (int i = k; i < N; ++i) {
      if (A(i, i) > best_d) {
        best_d = A(i, i);
        best = i;
      }
    }
    if (best < 0) break;
    if (best != k) {
      A.row(k).swap(A.row(best));
      A.col(k).swap(A.col(best));
      std::swap(b[k], b[best]);
    }
    const double d = A(k, k);
    out.statistic += 0.5 * b[k] * b[k] / d;
    for (int i = k + 1; i < N; ++i) {
      const double factor = A(i, k) / d;
      b[i] -= factor * b[k];
      for (int j = k + 1; j < N; ++j) A(i, j) -= factor * A(k, j);
    }
    ++out.rank;
  }
  return out;
}

/// The statistic of a satellite's group (three directions), as fitGroup<3> gives it: the
/// full-rank case of fitFullRank (same test, det(A) > tolerance) in closed form,
/// l = 1/2 f^T adj(R) f / det(R), with one division. It runs for every satellite and onset of
/// every epoch (240 times with 12 satellites), and saves about 3 % of the filter update's time
/// in glr_benchmark over fitGroup<3>. Otherwise (the newest onset, where a step and a ramp
/// coincide) the pivoted factorization decides.
double satelliteGroupStatistic(const Eigen::Matrix3d& R, const Eigen::Vector3d& f,
                               double tolerance) {
  const double c00 = R(1, 1) * R(2, 2) - R(1, 2) * R(1, 2);
  const double c11 = R(0, 0) * R(2, 2) - R(0, 2) * R(0, 2);
  const double c22 = R(0, 0) * R(1, 1) - R(0, 1) * R(0, 1);
  const double c01 = R(0, 2) * R(1, 2) - R(0, 1) * R(2, 2);
  const double c02 = R(0, 1) * R(1, 2) - R(0, 2) * R(1, 1);
  const double c12 = R(0, 1) * R(0, 2) - R(0, 0) * R(1, 2);
  const double det = R(0, 0) * c00 + R(0, 1) * c01 + R(0, 2) * c02;
  const double diag = R(0, 0) * R(1, 1) * R(2, 2);
  if (!(diag > 0.0) || !(det > tolerance * diag)) return fitGroup<3>(R, f, tolerance).statistic;
  const double q = c00 * f[0] * f[0] + c11 * f[1] * f[1] + c22 * f[2] * f[2] +
                   2.0 * (c01 * f[0] * f[1] + c02 * f[0] * f[2] + c12 * f[1] * f[2]);
  return 0.5 * q / det;
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
  f_.resize(kMaxDirections, config_.window);
  r_imu_.resize(kImuDirections * kImuDirections, config_.window);
  r_sat_.resize(kSatDirections * kSatDirections * kMaxSatellites, config_.window);
  const int columns = kMaxPropagated * config_.window;
  mu_.resize(kStates, columns);
  sizeWorkingBuffers();
  spacing_s_.resize(config_.window);
  reset();
}

void GlrMonitor::sizeWorkingBuffers() {
  const int columns = kMaxPropagated * config_.window;
  if (mu_next_->cols() != columns) mu_next_->resize(kStates, columns);
  if (ms_->cols() != columns) ms_->resize(kSupport, columns);
  if (z_->cols() != columns) z_->resize(kSupport, columns);
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
  mu_.setZero();
  spacing_s_.setZero();
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
  // A new satellite has no signature yet at any onset (its two propagated columns are
  // adjacent, so their blocks are too).
  mu_.middleCols(firstColumn(muColumn(slot, 0)), 2 * config_.window).setZero();
  f_.middleRows<kSatDirections>(satColumn(slot, 0)).setZero();
  r_sat_.middleRows<kSatDirections * kSatDirections>(kSatDirections * kSatDirections * slot)
      .setZero();
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
  // H must stay on the support (the pseudorange and rate model of the layout).
  if (!e.h.middleCols<kSupportTail.index - kSupportHead.end()>(kSupportHead.end()).isZero(0.0))
    return false;
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
    // H is zero outside the support (validate), so G H only touches the support's columns.
    b_ = e.phi;
    b_.middleCols<kSupportHead.dof>(kSupportHead.index).noalias() -=
        g_ * prev_h_support_.leftCols<kSupportHead.dof>();
    b_.middleCols<kSupportTail.dof>(kSupportTail.index).noalias() -=
        g_ * prev_h_support_.rightCols<kSupportTail.dof>();
  }
  prev_time_ns_ = time_ns_;
  time_ns_ = e.time_ns;
  // V = L L^T: V^-1 eps and V^-1 H by two triangular solves; the few entries of V^-1 the
  // direct inputs need (vInv) from the columns of L^-1.
  l_inv_.setIdentity(m, m);
  llt_.matrixL().solveInPlace(l_inv_);
  w_ = llt_.solve(e.innovation);
  // The statistics see the state only through H: everything below lives on H's support
  // (position, velocity and clock), which makes S mu an 8 x 8 product instead of n x n.
  h_support_.resize(m, kSupport);
  h_support_.leftCols<kSupportHead.dof>() = e.h.middleCols<kSupportHead.dof>(kSupportHead.index);
  h_support_.rightCols<kSupportTail.dof>() = e.h.middleCols<kSupportTail.dof>(kSupportTail.index);
  u_.resize(m, kSupport);
  u_ = llt_.solve(h_support_);
  s_.noalias() = h_support_.transpose() * u_;
  a_.noalias() = h_support_.transpose() * w_;
}

double GlrMonitor::vInv(int i, int j) const {
  // (V^-1)_ij = sum_k (L^-1)_ki (L^-1)_kj, over the rows where both columns can be nonzero.
  const int first = std::max(i, j);
  const int n = static_cast<int>(l_inv_.rows()) - first;
  return l_inv_.col(i).tail(n).dot(l_inv_.col(j).tail(n));
}

bool GlrMonitor::biasAndClockRowsSparse() const {
  // Random-constant biases and a clock that only the clock drives (the layout's error model)
  // make the bias and clock rows of Phi [0 I 0] and [0 0 Phi_clock] exactly, and G H only
  // adds support columns (attitude among them: the lever arm's).
  return b_.block<kBiasStates, kBiasStates>(kBiasIndex, kBiasIndex).isIdentity(0.0) &&
         b_.block<kSupportTail.dof, kBiasStates>(kSupportTail.index, kBiasIndex).isZero(0.0);
}

void GlrMonitor::propagate() {
  // mu_k = Phi_k (mu_{k-1} - K_{k-1} rho_{k-1}) = B mu_{k-1} - G D_{k-1}  (doc eq. C3), for
  // every onset and column in one product.
  const int columns = propagatedColumns() * config_.window;
  const auto in = mu_.leftCols(columns);
  auto out = mu_next_->leftCols(columns);
  if (biasAndClockRowsSparse()) {
    // Bias and receiver rows: B = [0 I 0] + B(:, support): support-wide per column, not n-wide.
    constexpr int kNav = layout::kAtt.end();  // position, velocity, attitude rows
    constexpr int kLower = kStates - kNav;    // bias and clock rows
    // (Eigen's kernels work on blocks of 4 rows: 8 rows as a product, the 9th alone.)
    out.topRows<kNav - 1>().noalias() = b_.topRows<kNav - 1>() * in;
    out.row(kNav - 1).noalias() = b_.row(kNav - 1) * in;
    out.bottomRows<kLower>().noalias() =
        b_.block<kLower, kSupportHead.dof>(kNav, kSupportHead.index) *
        in.middleRows<kSupportHead.dof>(kSupportHead.index);
    out.bottomRows<kLower>().noalias() +=
        b_.block<kLower, kSupportTail.dof>(kNav, kSupportTail.index) *
        in.middleRows<kSupportTail.dof>(kSupportTail.index);
    out.middleRows<kBiasStates>(kBiasIndex) += in.middleRows<kBiasStates>(kBiasIndex);
  } else {
    out.noalias() = b_ * in;
  }
  mu_.swap(*mu_next_);
  const bool range = config_.range_steps || config_.range_ramps;
  for (int s = 0; s < slots_used_; ++s) {
    const Slot& slot = slots_[static_cast<std::size_t>(s)];
    if (slot.prev_range_row >= 0 && range) {
      mu_.middleCols(firstColumn(muColumn(s, kRangeStep)), config_.window).colwise() -=
          g_.col(slot.prev_range_row) * kStepInput;
    }
    if (slot.prev_rate_row >= 0 && config_.rate_steps) {
      mu_.middleCols(firstColumn(muColumn(s, kRateStep)), config_.window).colwise() -=
          g_.col(slot.prev_rate_row) * kStepInput;
    }
  }
}

void GlrMonitor::startOnset(const GlrEpoch& e) {
  if (onset_count_ == config_.window) {
    onset_head_ = (onset_head_ + 1) % config_.window;  // the oldest onset leaves the window
    --onset_count_;
  }
  const int ring = (onset_head_ + onset_count_) % config_.window;
  Onset& o = onsets_[static_cast<std::size_t>(ring)];
  ++onset_count_;
  f_.col(ring).setZero();
  r_imu_.col(ring).setZero();
  r_sat_.col(ring).setZero();
  o.time_ns = e.time_ns;
  o.ramp_start_ns = prev_time_ns_;
  spacing_s_[ring] = 1e-9 * static_cast<double>(o.time_ns - o.ramp_start_ns);
  for (int c = 0; c < propagatedColumns(); ++c) mu_.col(firstColumn(c) + ring).setZero();
  if (config_.imu_steps) {
    // A bias step at the start of the interval: the bias error (estimate minus truth) drops by
    // the step, and Phi_k carries it to this epoch (doc eq. C4).
    for (int j = 0; j < kImuDirections; ++j)
      mu_.col(firstColumn(j) + ring) = -e.phi.col(imuState(j));
  }
}

void GlrMonitor::accumulate() {
  // rho_c = H mu_c + d_c e_{row_c}; f_c += rho_c^T V^-1 eps; R_cd += rho_c^T V^-1 rho_d
  // (eqs. 9-10), on H's support: ms_ = mu's support rows and z_ = S ms_ for every onset at once
  // (one block of `window` columns per direction); the direct inputs d enter in
  // accumulateSatellite.
  const int columns = propagatedColumns() * config_.window;
  ms_->topLeftCorner<kSupportHead.dof, Eigen::Dynamic>(kSupportHead.dof, columns) =
      mu_.block(kSupportHead.index, 0, kSupportHead.dof, columns);
  ms_->bottomLeftCorner<kSupportTail.dof, Eigen::Dynamic>(kSupportTail.dof, columns) =
      mu_.block(kSupportTail.index, 0, kSupportTail.dof, columns);
  z_->leftCols(columns).noalias() = s_ * ms_->leftCols(columns);
  if (config_.imu_steps) accumulateImu();
  for (int s = 0; s < slots_used_; ++s) accumulateSatellite(s);
}

// The sums are added to every ring position, active or not: a position that is not (yet) an
// onset is cleared when it becomes one (startOnset), and only active ones are read.
void GlrMonitor::accumulateImu() {
  const int window = config_.window;
  for (int c = 0; c < kImuDirections; ++c) {
    const auto mu_c = ms_->middleCols(firstColumn(c), window);
    f_.row(c).noalias() += a_.transpose() * mu_c;
    for (int d = c; d < kImuDirections; ++d) {
      const OnsetArray r =
          mu_c.cwiseProduct(z_->middleCols(firstColumn(d), window)).colwise().sum().array();
      r_imu_.row(c + kImuDirections * d) += r.matrix();
      if (d != c) r_imu_.row(d + kImuDirections * c) += r.matrix();
    }
  }
}

void GlrMonitor::accumulateSatellite(int s) {
  const Slot& slot = slots_[static_cast<std::size_t>(s)];
  using ConstColumn = Eigen::Map<const SupportVector>;
  const int window = config_.window;
  // Direct inputs d (doc: inputs table) and the rows they enter; an absent row has d = 0.
  const int rr = slot.range_row, tr = slot.rate_row;
  const double d_step = rr >= 0 ? kStepInput : 0.0;
  const double d_rate = tr >= 0 && config_.rate_steps ? kStepInput : 0.0;
  const SupportVector u_range =
      rr >= 0 ? SupportVector(u_.row(rr).transpose()) : SupportVector::Zero();
  const SupportVector u_rate =
      tr >= 0 ? SupportVector(u_.row(tr).transpose()) : SupportVector::Zero();
  const double w_range = rr >= 0 ? w_[rr] : 0.0, w_rate = tr >= 0 ? w_[tr] : 0.0;
  const double v_rr = rr >= 0 ? vInv(rr, rr) : 0.0;
  const double v_rt = rr >= 0 && tr >= 0 ? vInv(rr, tr) : 0.0;
  const double v_tt = tr >= 0 ? vInv(tr, tr) : 0.0;
  // Disabled hypotheses add nothing (their columns may still carry a ramp's steps).
  const double on_step = config_.range_steps ? 1.0 : 0.0;
  const double on_ramp = config_.range_ramps ? 1.0 : 0.0;
  const double on_rate = config_.rate_steps ? 1.0 : 0.0;
  const int step_first = firstColumn(muColumn(s, kRangeStep));
  const int rate_first = firstColumn(muColumn(s, kRateStep));
  const int r_first = kSatDirections * kSatDirections * s;
  // Newest onset to oldest: a ramp from onset theta is the sum of the steps from the onsets
  // theta and newer, each weighted by its epoch spacing (doc: ramps from steps).
  SupportVector ramp_mu = SupportVector::Zero(), ramp_z = SupportVector::Zero();
  double ramp_d = 0.0;
  int ring = (onset_head_ + onset_count_ - 1) % window;
  for (int age = 0; age < onset_count_; ++age, ring = ring == 0 ? window - 1 : ring - 1) {
    const ConstColumn mu_step(ms_->col(step_first + ring).data());
    const ConstColumn z_step(z_->col(step_first + ring).data());
    const ConstColumn mu_rate(ms_->col(rate_first + ring).data());
    const ConstColumn z_rate(z_->col(rate_first + ring).data());
    const double c = spacing_s_[ring];
    ramp_mu += c * mu_step;
    ramp_z += c * z_step;
    ramp_d += c * d_step;
    // f_c = mu_c^T a + d_c w(r_c)
    double* f = f_.col(ring).data() + satColumn(s, 0);
    f[kRangeStep] += on_step * (mu_step.dot(a_) + d_step * w_range);
    f[kRangeRamp] += on_ramp * (ramp_mu.dot(a_) + ramp_d * w_range);
    f[kRateStep] += on_rate * (mu_rate.dot(a_) + d_rate * w_rate);
    // R_ij = mu_i^T S mu_j + d_j U(r_j,:) mu_i + d_i U(r_i,:) mu_j + d_i d_j V^-1(r_i, r_j);
    // the range step and ramp enter the range row, the rate step the rate row.
    const double ur_step = u_range.dot(mu_step), ur_ramp = u_range.dot(ramp_mu);
    const double ur_rate = u_range.dot(mu_rate);
    const double ut_step = u_rate.dot(mu_step), ut_ramp = u_rate.dot(ramp_mu);
    const double ut_rate = u_rate.dot(mu_rate);
    const double ss = mu_step.dot(z_step) + 2.0 * d_step * ur_step + d_step * d_step * v_rr;
    const double pp = ramp_mu.dot(ramp_z) + 2.0 * ramp_d * ur_ramp + ramp_d * ramp_d * v_rr;
    const double tt = mu_rate.dot(z_rate) + 2.0 * d_rate * ut_rate + d_rate * d_rate * v_tt;
    const double sp =
        mu_step.dot(ramp_z) + ramp_d * ur_step + d_step * ur_ramp + d_step * ramp_d * v_rr;
    const double st =
        mu_step.dot(z_rate) + d_rate * ut_step + d_step * ur_rate + d_step * d_rate * v_rt;
    const double pt =
        ramp_mu.dot(z_rate) + d_rate * ut_ramp + ramp_d * ur_rate + ramp_d * d_rate * v_rt;
    Eigen::Map<Eigen::Matrix3d> R(r_sat_.col(ring).data() + r_first);
    R(kRangeStep, kRangeStep) += on_step * ss;
    R(kRangeRamp, kRangeRamp) += on_ramp * pp;
    R(kRateStep, kRateStep) += on_rate * tt;
    R(kRangeStep, kRangeRamp) += on_step * on_ramp * sp;
    R(kRangeStep, kRateStep) += on_step * on_rate * st;
    R(kRangeRamp, kRateStep) += on_ramp * on_rate * pt;
    R(kRangeRamp, kRangeStep) = R(kRangeStep, kRangeRamp);
    R(kRateStep, kRangeStep) = R(kRangeStep, kRateStep);
    R(kRateStep, kRangeRamp) = R(kRangeRamp, kRateStep);
  }
}

const GlrResult& GlrMonitor::update(const GlrEpoch& e) {
  if (!validate(e)) {
    ++refused_;
    result_ = GlrResult{};
    return result_;
  }
  sizeWorkingBuffers();
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
    propagate();
    startOnset(e);
  }
  accumulate();
  prev_h_support_ = h_support_;
  prev_k_ = e.k;
  have_previous_ = true;
  evaluate();
  return result_;
}

int GlrMonitor::onsetIndex(int age) const {
  const int i = onset_count_ - 1 - std::clamp(age, 0, std::max(onset_count_ - 1, 0));
  return (onset_head_ + i) % config_.window;
}

GlrMonitor::OnsetView GlrMonitor::onset(int age) const {
  const int ring = onsetIndex(age);
  return {onsets_[static_cast<std::size_t>(ring)].ramp_start_ns,
          Eigen::Map<const Eigen::Matrix<double, kMaxDirections, 1>>(f_.col(ring).data()),
          Eigen::Map<const Eigen::Matrix<double, kImuDirections, kImuDirections>>(
              r_imu_.col(ring).data()),
          r_sat_.col(ring).data()};
}

GlrMonitor::DirectionSums GlrMonitor::directionSums(int age, const GlrHypothesis& h) const {
  if (age < 0 || age >= onset_count_) return {};
  const OnsetView o = onset(age);
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
  return {o.f[satColumn(slot, j)], o.rSat(slot)(j, j)};
}

double GlrMonitor::imuStatistic(int age) const {
  if (age < 0 || age >= onset_count_) return 0.0;
  const OnsetView o = onset(age);
  return fitGroup<kImuDirections>(o.r_imu, o.f.head<kImuDirections>(), config_.rank_tolerance)
      .statistic;
}

double GlrMonitor::satelliteStatistic(int age, int sv_id) const {
  if (age < 0 || age >= onset_count_ || sv_id < 1 || sv_id > 32) return 0.0;
  const int slot = slot_of_sv_[static_cast<std::size_t>(sv_id)] - 1;
  if (slot < 0) return 0.0;
  const OnsetView o = onset(age);
  const Eigen::Vector3d f = o.f.segment<kSatDirections>(satColumn(slot, 0));
  return fitGroup<kSatDirections>(o.rSat(slot), f, config_.rank_tolerance).statistic;
}

void GlrMonitor::positionSignatures(std::vector<PositionSignature>& out) const {
  out.clear();
  if (!have_previous_ || onset_count_ == 0) return;
  // mu+ = mu - K (H mu + D) on the position rows (doc eqs. C1, C3), with this epoch's K and H.
  constexpr int kPos = layout::kPos.index;
  const Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxRows> k_pos =
      prev_k_.middleRows<3>(kPos);
  const Eigen::Matrix<double, 3, kSupport> kh = k_pos * prev_h_support_;
  const auto after = [&](int column, double d, int row) {
    Eigen::Vector3d p = mu_.block<3, 1>(kPos, column) - kh * ms_->col(column);
    if (row >= 0) p -= d * k_pos.col(row);
    return p;
  };
  if (config_.imu_steps) {
    for (int age = 0; age < onset_count_; ++age) {
      const int ring = onsetIndex(age);
      const OnsetView o = onset(age);
      for (int j = 0; j < kImuDirections; ++j) {
        const GlrHypothesis h{j < 3 ? GlrFault::kAccelStep : GlrFault::kGyroStep, j % 3, 0};
        out.push_back({h, age, after(firstColumn(j) + ring, 0.0, -1), o.r_imu(j, j)});
      }
    }
  }
  for (int s = 0; s < slots_used_; ++s) {
    const Slot& slot = slots_[static_cast<std::size_t>(s)];
    if (slot.quarantined) continue;
    const int step_first = firstColumn(muColumn(s, kRangeStep));
    const int rate_first = firstColumn(muColumn(s, kRateStep));
    // Newest onset to oldest: a ramp is the spacing-weighted sum of the newer steps (doc: ramps
    // from steps), and so is its effect, the map from signature to effect being linear.
    Eigen::Vector3d ramp = Eigen::Vector3d::Zero();
    for (int age = 0; age < onset_count_; ++age) {
      const int ring = onsetIndex(age);
      const OnsetView o = onset(age);
      const Eigen::Matrix3d r = o.rSat(s);
      const Eigen::Vector3d step = after(step_first + ring, kStepInput, slot.range_row);
      ramp += spacing_s_[ring] * step;
      if (config_.range_steps)
        out.push_back(
            {{GlrFault::kRangeStep, 0, slot.sv_id}, age, step, r(kRangeStep, kRangeStep)});
      if (config_.range_ramps)
        out.push_back(
            {{GlrFault::kRangeRamp, 0, slot.sv_id}, age, ramp, r(kRangeRamp, kRangeRamp)});
      if (config_.rate_steps)
        out.push_back({{GlrFault::kRateStep, 0, slot.sv_id},
                       age,
                       after(rate_first + ring, kStepInput, slot.rate_row),
                       r(kRateStep, kRateStep)});
    }
  }
}

double GlrMonitor::onsetStatistic(const OnsetView& o) const {
  double l = 0.0;
  if (config_.imu_steps) {
    l = fitGroup<kImuDirections>(o.r_imu, o.f.head<kImuDirections>(), config_.rank_tolerance)
            .statistic;
  }
  for (int s = 0; s < slots_used_; ++s) {
    if (slots_[static_cast<std::size_t>(s)].quarantined) continue;
    const Eigen::Vector3d f = o.f.segment<kSatDirections>(satColumn(s, 0));
    l = std::max(l, satelliteGroupStatistic(o.rSat(s), f, config_.rank_tolerance));
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
  result_.statistic = best;
  result_.detected = best >= config_.threshold;
  const OnsetView o = onset(best_age);
  if (result_.detected) {
    isolate(o, best_age, result_);  // eqs. 14-16 at detection time
  } else {
    result_.onset_epochs_ago = best_age;
    result_.onset_time_ns = o.ramp_start_ns;
  }
}

GlrResult GlrMonitor::isolationAt(int onset_age) const {
  GlrResult r;
  if (onset_age < 0 || onset_age >= onset_count_) return r;
  r.valid = true;
  r.threshold = config_.threshold;
  const OnsetView o = onset(onset_age);
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

void GlrMonitor::isolate(const OnsetView& o, int onset_age, GlrResult& r) const {
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
    const GroupFit g = fitGroup<kSatDirections>(o.rSat(s), f, config_.rank_tolerance);
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
        scalar(o.f[satColumn(s, j)], o.rSat(s)(j, j), c);
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
