#include "navbus/core/integrity/glr_window.hpp"

#include <algorithm>
#include <cmath>

#include "navbus/core/math/column_product.hpp"

namespace navbus::core {

using namespace glr;

namespace {

/// D of a measurement step per unit magnitude: innovations are predicted minus measured, so a
/// measurement reading long by nu lowers them (doc: inputs table).
constexpr double kStepInput = -1.0;

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

}  // namespace

void GlrWindow::configure(const GlrConfig& config) {
  config_ = config;
  config_.window = std::clamp(config.window, 1, kMaxWindow);
  slot_capacity_ = glrSlotCapacity(config_);
  onsets_.assign(static_cast<std::size_t>(config_.window), Onset{});
  f_.resize(directions(slot_capacity_), config_.window);
  r_imu_.resize(kImuDirections * kImuDirections, config_.window);
  r_sat_.resize(kSatDirections * kSatDirections * slot_capacity_, config_.window);
  mu_.resize(kStates, propagated(slot_capacity_) * config_.window);
  sizeWorkingBuffers();
  spacing_s_.resize(config_.window);
  reset();
}

void GlrWindow::sizeWorkingBuffers() {
  Work& work = *work_;
  const int columns = propagated(slot_capacity_) * config_.window;
  if (work.mu_next.cols() != columns) work.mu_next.resize(kStates, columns);
  if (work.z.cols() != columns) work.z.resize(kSupport, columns);
}

void GlrWindow::reset() {
  onset_head_ = 0;
  onset_count_ = 0;
  have_previous_ = false;
  // Quarantine is a decision of the fault manager: it survives a reset of the statistics.
  std::array<int, 33> quarantined{};
  for (int sv = 1; sv <= 32; ++sv)
    quarantined[static_cast<std::size_t>(sv)] = this->quarantined(sv);
  slots_ = {};
  slots_used_ = 0;
  slot_of_sv_ = {};
  mu_.setZero();
  live_count_ = 0;
  row_of_.fill(-1);
  support_count_ = 0;
  spacing_s_.setZero();
  for (int sv = 1; sv <= 32; ++sv) {
    if (quarantined[static_cast<std::size_t>(sv)]) setQuarantined(sv, true);
  }
}

void GlrWindow::claimSlot(int slot, int sv_id, std::int64_t receiver) {
  Slot& claimed = slots_[static_cast<std::size_t>(slot)];
  const Slot old = claimed;
  if (old.sv_id > 0 && old.receiver == GlrHypothesis::kEveryReceiver)
    slot_of_sv_[static_cast<std::size_t>(old.sv_id)] = 0;
  // A receiver's slot of a quarantined satellite is quarantined with it.
  const bool quarantined = this->quarantined(sv_id);
  claimed = Slot{};
  claimed.sv_id = sv_id;
  claimed.receiver = receiver;
  claimed.last_seen = epochs_;
  claimed.quarantined = quarantined;
  if (receiver == GlrHypothesis::kEveryReceiver)
    slot_of_sv_[static_cast<std::size_t>(sv_id)] = slot + 1;
  // A new satellite has no signature yet at any onset (its two propagated columns are
  // adjacent, so their blocks are too).
  mu_.middleCols(firstColumn(muColumn(slot, 0)), 2 * config_.window).setZero();
  f_.middleRows<kSatDirections>(satColumn(slot, 0)).setZero();
  r_sat_.middleRows<kSatDirections * kSatDirections>(kSatDirections * kSatDirections * slot)
      .setZero();
}

void GlrWindow::setQuarantined(int sv_id, bool quarantined) {
  if (sv_id < 1 || sv_id > 32) return;
  if (slot_of_sv_[static_cast<std::size_t>(sv_id)] == 0) {
    if (!quarantined || slots_used_ >= slot_capacity_) return;
    claimSlot(slots_used_++, sv_id, GlrHypothesis::kEveryReceiver);
  }
  // The satellite's own slot and its receivers' slots.
  for (int s = 0; s < slots_used_; ++s) {
    Slot& slot = slots_[static_cast<std::size_t>(s)];
    if (slot.sv_id == sv_id) slot.quarantined = quarantined;
  }
}

bool GlrWindow::quarantined(int sv_id) const {
  if (sv_id < 1 || sv_id > 32) return false;
  const int slot = slot_of_sv_[static_cast<std::size_t>(sv_id)] - 1;
  return slot >= 0 && slots_[static_cast<std::size_t>(slot)].quarantined;
}

bool GlrWindow::accepts(const GlrEpoch& e) const {
  if (e.rows < 1 || e.rows > kMaxRows || e.innovation.size() != e.rows ||
      e.innovation_cov.rows() != e.rows || e.innovation_cov.cols() != e.rows ||
      e.h.rows() != e.rows || e.k.cols() != e.rows)
    return false;
  std::array<std::array<int, 2>, 33> rows_of_sv{};  // range and rate rows per PRN
  for (int r = 0; r < e.rows; ++r) {
    const int sv = e.sv_id[static_cast<std::size_t>(r)];
    if (sv < 1 || sv > 32) return false;
    int& n =
        rows_of_sv[static_cast<std::size_t>(sv)][e.is_rate[static_cast<std::size_t>(r)] ? 1 : 0];
    if (++n > layout::kMaxFusedReceivers) return false;
  }
  // H must stay on the support (the pseudorange and rate model of the layout).
  if (!e.h.middleCols<kSupportTail.index - kSupportHead.end()>(kSupportHead.end()).isZero(0.0))
    return false;
  return e.innovation.allFinite() && e.innovation_cov.allFinite() && e.h.allFinite() &&
         e.k.allFinite() && e.phi.allFinite() && (!have_previous_ || e.time_ns > time_ns_);
}

bool GlrWindow::update(const GlrEpoch& e) {
  Work& work = *work_;
  sizeWorkingBuffers();
  work.llt.compute(e.innovation_cov);  // used again for V^-1 in prepareEpoch
  if (work.llt.info() != Eigen::Success) return false;
  ++epochs_;
  assignSlots(e);
  const bool had_previous = have_previous_;
  prepareEpoch(e);
  if (had_previous) {
    growLive(e);
    propagate();
    startOnset(e);
  }
  prepareSupport(e);
  accumulate();
  prev_h_fixed_.resize(e.rows, kSupport);
  prev_h_fixed_.leftCols<kSupportHead.dof>() = e.h.middleCols<kSupportHead.dof>(kSupportHead.index);
  prev_h_fixed_.rightCols<kSupportTail.dof>() =
      e.h.middleCols<kSupportTail.dof>(kSupportTail.index);
  prev_k_ = e.k;
  have_previous_ = true;
  return true;
}

int GlrWindow::slotOf(int sv_id, std::int64_t receiver) const {
  if (sv_id < 1 || sv_id > 32) return -1;
  if (receiver == GlrHypothesis::kEveryReceiver)
    return slot_of_sv_[static_cast<std::size_t>(sv_id)] - 1;
  for (int s = 0; s < slots_used_; ++s) {
    const Slot& slot = slots_[static_cast<std::size_t>(s)];
    if (slot.sv_id == sv_id && slot.receiver == receiver) return s;
  }
  return -1;
}

GlrHypothesis GlrWindow::hypothesis(int slot, int direction) const {
  const Slot& s = slots_[static_cast<std::size_t>(slot)];
  const GlrFault fault = direction == kRangeStep   ? GlrFault::kRangeStep
                         : direction == kRangeRamp ? GlrFault::kRangeRamp
                                                   : GlrFault::kRateStep;
  return {fault, 0, s.sv_id, s.receiver};
}

bool GlrWindow::perReceiverSlots(const GlrEpoch& e) const {
  if (!config_.per_receiver_satellites) return false;
  for (int r = 1; r < e.rows; ++r) {
    if (e.receiver[static_cast<std::size_t>(r)] != e.receiver[0]) return true;
  }
  return false;
}

int GlrWindow::slotFor(int sv_id, std::int64_t receiver) {
  int slot = slotOf(sv_id, receiver);
  if (slot >= 0) return slot;
  // A slot whose satellite has not been seen for a whole window carries no signature any more
  // (every onset that saw it has left the window): reuse it.
  for (int s = 0; s < slots_used_ && slot < 0; ++s) {
    const Slot& old = slots_[static_cast<std::size_t>(s)];
    if (!old.quarantined && epochs_ - old.last_seen > static_cast<std::uint64_t>(config_.window))
      slot = s;
  }
  if (slot < 0) {
    // Cannot happen with <= kMaxSatellites satellites (and as many receiver-satellite
    // observations) per epoch.
    if (slots_used_ >= slot_capacity_) return -1;
    slot = slots_used_++;
  }
  claimSlot(slot, sv_id, receiver);
  return slot;
}

void GlrWindow::assignSlots(const GlrEpoch& e) {
  for (int s = 0; s < slots_used_; ++s) {
    Slot& slot = slots_[static_cast<std::size_t>(s)];
    slot.prev_range = slot.range;
    slot.prev_rate = slot.rate;
    slot.range = slot.rate = Rows{};
  }
  const bool per_receiver = perReceiverSlots(e);
  auto assign = [&](int slot, int r) {
    if (slot < 0) return;
    Slot& s = slots_[static_cast<std::size_t>(slot)];
    s.last_seen = epochs_;
    Rows& rows = e.is_rate[static_cast<std::size_t>(r)] ? s.rate : s.range;
    rows.row[static_cast<std::size_t>(rows.count++)] = r;  // accepts() bounds the count
  };
  for (int r = 0; r < e.rows; ++r) {
    const int sv = e.sv_id[static_cast<std::size_t>(r)];
    assign(slotFor(sv, GlrHypothesis::kEveryReceiver), r);
    if (per_receiver) assign(slotFor(sv, e.receiver[static_cast<std::size_t>(r)]), r);
  }
}

void GlrWindow::prepareEpoch(const GlrEpoch& e) {
  Work& work = *work_;
  const int m = e.rows;
  if (have_previous_) {
    // Closed-loop transition from the previous epoch's prior to this one's (doc eq. C3).
    work.g.resize(kStates, prev_k_.cols());
    work.g.noalias() = e.phi * prev_k_;
    // H is zero outside the support (validate), so G H only touches the support's columns.
    work.b = e.phi;
    work.b.middleCols<kSupportHead.dof>(kSupportHead.index).noalias() -=
        work.g * prev_h_fixed_.leftCols<kSupportHead.dof>();
    work.b.middleCols<kSupportTail.dof>(kSupportTail.index).noalias() -=
        work.g * prev_h_fixed_.rightCols<kSupportTail.dof>();
  }
  prev_time_ns_ = time_ns_;
  time_ns_ = e.time_ns;
  // V = L L^T: V^-1 eps and V^-1 H by two triangular solves; the few entries of V^-1 the
  // direct inputs need (vInv) from the columns of L^-1.
  work.l_inv.setIdentity(m, m);
  work.llt.matrixL().solveInPlace(work.l_inv);
  work.w = work.llt.solve(e.innovation);
}

void GlrWindow::addLive(int state) {
  if (row_of_[static_cast<std::size_t>(state)] >= 0) return;
  row_of_[static_cast<std::size_t>(state)] = live_count_;
  live_[static_cast<std::size_t>(live_count_)] = state;
  mu_.row(live_count_++).setZero();  // no signature has reached it (the row may be stale)
}

void GlrWindow::growLive(const GlrEpoch& e) {
  Work& work = *work_;
  // What the recursion below can make nonzero: B's rows that read a live state, G's rows (the
  // measurement inputs, doc eq. C3) and the IMU steps' inputs Phi(:, bias) (doc eq. C4). A row
  // added now is zero, so its own column of B does not matter this epoch.
  const int live_before = live_count_;
  for (int i = 0; i < kStates; ++i) {
    if (row_of_[static_cast<std::size_t>(i)] >= 0) continue;
    bool reached = !work.g.row(i).isZero(0.0);
    for (int r = 0; r < live_before && !reached; ++r)
      reached = work.b(i, live_[static_cast<std::size_t>(r)]) != 0.0;
    for (int j = 0; j < kImuDirections && !reached && config_.imu_steps; ++j)
      reached = e.phi(i, imuState(j)) != 0.0;
    if (reached) addLive(i);
  }
}

void GlrWindow::reorderLive(const std::array<int, kStates>& first, int count) {
  Work& work = *work_;
  // The new order: `first`, then the other live states as they were; mu's rows follow (through
  // the working buffer). Runs when the support changes, not every epoch.
  std::array<int, kStates> order = first;
  int n = count;
  for (int r = 0; r < live_count_; ++r) {
    const int state = live_[static_cast<std::size_t>(r)];
    if (std::find(first.begin(), first.begin() + count, state) == first.begin() + count)
      order[static_cast<std::size_t>(n++)] = state;
  }
  const int columns = static_cast<int>(mu_.cols());
  for (int r = 0; r < n; ++r) {
    const int state = order[static_cast<std::size_t>(r)];
    work.mu_next.row(r) = mu_.row(row_of_[static_cast<std::size_t>(state)]).head(columns);
  }
  mu_.swap(work.mu_next);
  for (int r = 0; r < n; ++r) {
    live_[static_cast<std::size_t>(r)] = order[static_cast<std::size_t>(r)];
    row_of_[static_cast<std::size_t>(order[static_cast<std::size_t>(r)])] = r;
  }
}

double GlrWindow::vInv(int i, int j) const {
  const Work& work = *work_;
  // (V^-1)_ij = sum_k (L^-1)_ki (L^-1)_kj, over the rows where both columns can be nonzero.
  const int first = std::max(i, j);
  const int n = static_cast<int>(work.l_inv.rows()) - first;
  return work.l_inv.col(i).tail(n).dot(work.l_inv.col(j).tail(n));
}

void GlrWindow::propagate() {
  Work& work = *work_;
  // mu_k = Phi_k (mu_{k-1} - K_{k-1} rho_{k-1}) = B mu_{k-1} - G D_{k-1}  (doc eq. C3), for
  // every onset and column in one product, on the live rows. (Splitting off B's identity on
  // the random-constant biases saves a quarter of the multiplications and costs more than that
  // in a second product and pass on this size, measured.)
  const int n = live_count_;
  work.b_live.resize(n, n);
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r < n; ++r)
      work.b_live(r, c) =
          work.b(live_[static_cast<std::size_t>(r)], live_[static_cast<std::size_t>(c)]);
  }
  const int columns = propagatedColumns() * config_.window;
  columnProduct(n, columns, work.b_live.data(), static_cast<int>(work.b_live.outerStride()),
                mu_.data(), static_cast<int>(mu_.outerStride()), work.mu_next.data(),
                static_cast<int>(work.mu_next.outerStride()));
  mu_.swap(work.mu_next);
  const bool range = config_.range_steps || config_.range_ramps;
  for (int s = 0; s < slots_used_; ++s) {
    const Slot& slot = slots_[static_cast<std::size_t>(s)];
    // A satellite's fault entered each receiver's row of it.
    if (range)
      for (const int row : slot.prev_range) subtractInput(muColumn(s, kRangeStep), row);
    if (config_.rate_steps)
      for (const int row : slot.prev_rate) subtractInput(muColumn(s, kRateStep), row);
  }
}

void GlrWindow::subtractInput(int column, int row) {
  Work& work = *work_;
  // - G D: the direct input d = kStepInput entered row `row` of the previous epoch.
  const int n = live_count_;
  work.g_live.resize(n);
  for (int r = 0; r < n; ++r) work.g_live[r] = work.g(live_[static_cast<std::size_t>(r)], row);
  mu_.block(0, firstColumn(column), n, config_.window).colwise() -= work.g_live * kStepInput;
}

void GlrWindow::startOnset(const GlrEpoch& e) {
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
  for (int c = 0; c < propagatedColumns(); ++c)
    mu_.col(firstColumn(c) + ring).head(live_count_).setZero();
  if (config_.imu_steps) {
    // A bias step at the start of the interval: the bias error (estimate minus truth) drops by
    // the step, and Phi_k carries it to this epoch (doc eq. C4); growLive made its rows live.
    for (int j = 0; j < kImuDirections; ++j) {
      for (int r = 0; r < live_count_; ++r)
        mu_(r, firstColumn(j) + ring) = -e.phi(live_[static_cast<std::size_t>(r)], imuState(j));
    }
  }
}

void GlrWindow::prepareSupport(const GlrEpoch& e) {
  Work& work = *work_;
  // The statistics see the state only through H: everything below lives on H's support, the
  // live states with a nonzero column in H (position, velocity, the clock, and attitude only
  // with a lever arm), which makes S mu an 8 x 8 product instead of n x n. The support is kept
  // as the leading live rows, so that mu's first rows are what f and R read.
  const int m = e.rows;
  std::array<int, kStates> order{};
  int count = 0;
  for (int i = 0; i < kStates; ++i) {
    if (row_of_[static_cast<std::size_t>(i)] >= 0 && !e.h.col(i).isZero(0.0))
      order[static_cast<std::size_t>(count++)] = i;
  }
  bool leading = true;
  for (int k = 0; k < count && leading; ++k)
    leading = row_of_[static_cast<std::size_t>(order[static_cast<std::size_t>(k)])] < count;
  if (!leading || count != support_count_) reorderLive(order, count);
  support_count_ = count;
  h_support_.resize(m, count);
  for (int c = 0; c < count; ++c) h_support_.col(c) = e.h.col(live_[static_cast<std::size_t>(c)]);
  work.u.resize(m, count);
  work.u = work.llt.solve(h_support_);
  work.s.resize(count, count);
  work.s.noalias() = h_support_.transpose() * work.u;
  work.a.resize(count);
  work.a.noalias() = h_support_.transpose() * work.w;
}

void GlrWindow::accumulate() {
  Work& work = *work_;
  // rho_c = H mu_c + d_c e_{row_c}; f_c += rho_c^T V^-1 eps; R_cd += rho_c^T V^-1 rho_d
  // (eqs. 9-10), on H's support: mu's leading rows and z_ = S mu there for every onset at once
  // (one block of `window` columns per direction); the direct inputs d enter in
  // accumulateSatellite.
  const int columns = propagatedColumns() * config_.window;
  const int n = support_count_;
  columnProduct(n, columns, work.s.data(), static_cast<int>(work.s.outerStride()), mu_.data(),
                static_cast<int>(mu_.outerStride()), work.z.data(),
                static_cast<int>(work.z.outerStride()));
  if (config_.imu_steps) accumulateImu();
  // The satellites' sums are support-wide dot products, many per onset: with the support's size
  // known at compile time for the usual cases (position, velocity and clock; with a lever arm,
  // the attitude too) they are a third of the cost.
  for (int s = 0; s < slots_used_; ++s) {
    if (n == 8) {
      accumulateSatellite<8>(s);
    } else if (n == 11) {
      accumulateSatellite<11>(s);
    } else {
      accumulateSatellite<Eigen::Dynamic>(s);
    }
  }
}

// The sums are added to every ring position, active or not: a position that is not (yet) an
// onset is cleared when it becomes one (startOnset), and only active ones are read.
void GlrWindow::accumulateImu() {
  Work& work = *work_;
  const int window = config_.window;
  for (int c = 0; c < kImuDirections; ++c) {
    const auto mu_c = mu_.block(0, firstColumn(c), support_count_, window);
    f_.row(c).noalias() += work.a.transpose() * mu_c;
    for (int d = c; d < kImuDirections; ++d) {
      const OnsetArray r =
          mu_c.cwiseProduct(work.z.block(0, firstColumn(d), support_count_, window))
              .colwise()
              .sum()
              .array();
      r_imu_.row(c + kImuDirections * d) += r.matrix();
      if (d != c) r_imu_.row(d + kImuDirections * c) += r.matrix();
    }
  }
}

template <int N>
void GlrWindow::accumulateSatellite(int s) {
  Work& work = *work_;
  const Slot& slot = slots_[static_cast<std::size_t>(s)];
  using Vector = Eigen::Matrix<double, N, 1, 0, N == Eigen::Dynamic ? kSupport : N, 1>;
  using ConstColumn = Eigen::Map<const Vector>;
  const int window = config_.window;
  const int n = support_count_;
  // Direct inputs d (doc: inputs table) and the rows they enter; an absent row has d = 0.
  // With several receivers' rows of the satellite, d enters each: its terms below are sums
  // over those rows (U D = sum of U's rows, D^T V^-1 D = sum of the block's entries).
  const Rows& range_rows = slot.range;
  const Rows& rate_rows = slot.rate;
  const double d_step = range_rows.any() ? kStepInput : 0.0;
  const double d_rate = rate_rows.any() && config_.rate_steps ? kStepInput : 0.0;
  Vector u_range = Vector::Zero(n), u_rate = Vector::Zero(n);
  double w_range = 0.0, w_rate = 0.0, v_rr = 0.0, v_rt = 0.0, v_tt = 0.0;
  for (const int i : range_rows) {
    u_range += work.u.row(i).transpose();
    w_range += work.w[i];
    for (const int j : range_rows) v_rr += vInv(i, j);
    for (const int j : rate_rows) v_rt += vInv(i, j);
  }
  for (const int i : rate_rows) {
    u_rate += work.u.row(i).transpose();
    w_rate += work.w[i];
    for (const int j : rate_rows) v_tt += vInv(i, j);
  }
  // Disabled hypotheses add nothing (their columns may still carry a ramp's steps).
  const double on_step = config_.range_steps ? 1.0 : 0.0;
  const double on_ramp = config_.range_ramps ? 1.0 : 0.0;
  const double on_rate = config_.rate_steps ? 1.0 : 0.0;
  const int step_first = firstColumn(muColumn(s, kRangeStep));
  const int rate_first = firstColumn(muColumn(s, kRateStep));
  const int r_first = kSatDirections * kSatDirections * s;
  // Newest onset to oldest: a ramp from onset theta is the sum of the steps from the onsets
  // theta and newer, each weighted by its epoch spacing (doc: ramps from steps).
  Vector ramp_mu = Vector::Zero(n), ramp_z = Vector::Zero(n);
  double ramp_d = 0.0;
  int ring = (onset_head_ + onset_count_ - 1) % window;
  for (int age = 0; age < onset_count_; ++age, ring = ring == 0 ? window - 1 : ring - 1) {
    const ConstColumn mu_step(mu_.col(step_first + ring).data(), n);
    const ConstColumn z_step(work.z.col(step_first + ring).data(), n);
    const ConstColumn mu_rate(mu_.col(rate_first + ring).data(), n);
    const ConstColumn z_rate(work.z.col(rate_first + ring).data(), n);
    const double c = spacing_s_[ring];
    ramp_mu += c * mu_step;
    ramp_z += c * z_step;
    ramp_d += c * d_step;
    // f_c = mu_c^T a + d_c w(r_c)
    double* f = f_.col(ring).data() + satColumn(s, 0);
    f[kRangeStep] += on_step * (mu_step.dot(work.a) + d_step * w_range);
    f[kRangeRamp] += on_ramp * (ramp_mu.dot(work.a) + ramp_d * w_range);
    f[kRateStep] += on_rate * (mu_rate.dot(work.a) + d_rate * w_rate);
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

int GlrWindow::onsetIndex(int age) const {
  const int i = onset_count_ - 1 - std::clamp(age, 0, std::max(onset_count_ - 1, 0));
  return (onset_head_ + i) % config_.window;
}

GlrWindow::OnsetView GlrWindow::onset(int age) const {
  const int ring = onsetIndex(age);
  return {onsets_[static_cast<std::size_t>(ring)].ramp_start_ns,
          Eigen::Map<const Eigen::VectorXd>(f_.col(ring).data(), f_.rows()),
          Eigen::Map<const Eigen::Matrix<double, kImuDirections, kImuDirections>>(
              r_imu_.col(ring).data()),
          r_sat_.col(ring).data()};
}

void GlrWindow::positionSignatures(std::vector<PositionSignature>& out) const {
  out.clear();
  if (!have_previous_ || onset_count_ == 0) return;
  // mu+ = mu - K (H mu + D) on the position rows (doc eqs. C1, C3), with this epoch's K and H.
  constexpr int kPosRow = layout::kPos.index;
  const Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxRows> k_pos =
      prev_k_.middleRows<3>(kPosRow);
  const Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kSupport> kh = k_pos * h_support_;
  const auto after = [&](int column, double d, const Rows& rows) {
    Eigen::Vector3d p = -kh * mu_.col(column).head(support_count_);
    for (int i = 0; i < 3; ++i) {
      const int live_row = row_of_[static_cast<std::size_t>(kPosRow + i)];
      if (live_row >= 0) p[i] += mu_(live_row, column);
    }
    for (const int row : rows) p -= d * k_pos.col(row);
    return p;
  };
  if (config_.imu_steps) {
    for (int age = 0; age < onset_count_; ++age) {
      const int ring = onsetIndex(age);
      const OnsetView o = onset(age);
      for (int j = 0; j < kImuDirections; ++j) {
        const GlrHypothesis h{j < 3 ? GlrFault::kAccelStep : GlrFault::kGyroStep, j % 3, 0};
        out.push_back({h, age, after(firstColumn(j) + ring, 0.0, Rows{}), o.r_imu(j, j)});
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
      const Eigen::Vector3d step = after(step_first + ring, kStepInput, slot.range);
      ramp += spacing_s_[ring] * step;
      if (config_.range_steps)
        out.push_back({hypothesis(s, kRangeStep), age, step, r(kRangeStep, kRangeStep)});
      if (config_.range_ramps)
        out.push_back({hypothesis(s, kRangeRamp), age, ramp, r(kRangeRamp, kRangeRamp)});
      if (config_.rate_steps)
        out.push_back({hypothesis(s, kRateStep), age,
                       after(rate_first + ring, kStepInput, slot.rate), r(kRateStep, kRateStep)});
    }
  }
}

}  // namespace navbus::core
