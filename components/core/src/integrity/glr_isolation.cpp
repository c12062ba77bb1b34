#include "navbus/core/integrity/glr_isolation.hpp"

#include <algorithm>
#include <cmath>

#include "navbus/core/integrity/glr_group_fit.hpp"
#include "navbus/core/math/chi_square.hpp"

namespace navbus::core {

using namespace glr;

void isolateOnset(const GlrWindow& window, const GlrConfig& config, int onset_age, GlrResult& r) {
  const GlrWindow::OnsetView o = window.onset(onset_age);
  r.onset_epochs_ago = onset_age;
  r.onset_time_ns = o.ramp_start_ns;
  r.onset_censored = window.onsetCount() == window.window() && onset_age == window.onsetCount() - 1;
  // INS against GNSS (seed 000 sec. 3): the group whose statistic is least likely under no
  // fault, given its number of identifiable directions.
  if (config.imu_steps) {
    const GroupFit g =
        glr::fitGroup<kImuDirections>(o.r_imu, o.f.head<kImuDirections>(), config.rank_tolerance);
    r.imu_statistic = g.statistic;
    r.imu_rank = g.rank;
    r.imu_significance = chiSquareSignificance(2.0 * g.statistic, g.rank);
  }
  int best_slot = -1;
  for (int s = 0; s < window.slotsUsed(); ++s) {
    if (window.slot(s).quarantined) continue;
    const Eigen::Vector3d f = o.f.segment<kSatDirections>(satColumn(s, 0));
    const GroupFit g = glr::fitGroup<kSatDirections>(o.rSat(s), f, config.rank_tolerance);
    const double sig = chiSquareSignificance(2.0 * g.statistic, g.rank);
    if (best_slot < 0 || sig > r.satellite_significance) {
      best_slot = s;
      r.satellite_statistic = g.statistic;
      r.satellite_rank = g.rank;
      r.satellite_significance = sig;
    }
  }
  const bool imu =
      config.imu_steps && (best_slot < 0 || r.imu_significance >= r.satellite_significance);
  r.source = imu ? GlrSourceClass::kImu
                 : (best_slot >= 0 ? GlrSourceClass::kSatellite : GlrSourceClass::kNone);
  // Which direction (eqs. 14-15 with T a unit vector): f* = f_j, R* = R_jj.
  std::array<GlrCandidate, kMaxSlots + kImuDirections> all{};
  std::array<int, kMaxSlots + kImuDirections> column{};
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
    // One candidate per satellite: its most likely fault kind, in every receiver's rows of it
    // or (per-receiver hypotheses) in one receiver's.
    std::array<int, 33> candidate_of_sv{};  // PRN -> index in `all` + 1
    for (int s = 0; s < window.slotsUsed(); ++s) {
      const GlrWindow::Slot& slot = window.slot(s);
      if (slot.quarantined) continue;
      GlrCandidate best;
      for (int j = 0; j < kSatDirections; ++j) {
        GlrCandidate c;
        c.hypothesis = window.hypothesis(s, j);
        scalar(o.f[satColumn(s, j)], o.rSat(s)(j, j), c);
        if (c.statistic > best.statistic || j == 0) best = c;
      }
      int& index = candidate_of_sv[static_cast<std::size_t>(slot.sv_id)];
      if (index == 0) {
        all[static_cast<std::size_t>(count)] = best;
        index = ++count;
      } else if (best.statistic > all[static_cast<std::size_t>(index - 1)].statistic) {
        all[static_cast<std::size_t>(index - 1)] = best;
      }
    }
  }
  std::array<int, kMaxSlots + kImuDirections> order{};
  for (int i = 0; i < count; ++i) order[static_cast<std::size_t>(i)] = i;
  std::sort(order.begin(), order.begin() + count, [&](int a, int b) {
    return all[static_cast<std::size_t>(a)].statistic > all[static_cast<std::size_t>(b)].statistic;
  });
  r.candidate_count = std::min(count, static_cast<int>(r.candidates.size()));
  for (int i = 0; i < r.candidate_count; ++i)
    r.candidates[static_cast<std::size_t>(i)] =
        all[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
  if (r.candidate_count < 2) return;
  r.ambiguous = r.candidates[1].statistic >= r.candidates[0].statistic - config.ambiguity_margin;
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
  if (std::abs(corr(best, twin)) >= config.ambiguity_correlation) {
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
