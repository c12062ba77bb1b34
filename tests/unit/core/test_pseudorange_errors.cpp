// The satellites' time-correlated pseudorange errors: which state holds which satellite, the
// states' column of H (the prediction against its numerical difference) and of Phi (the
// Gauss-Markov decay and its stationary variance).
#include <cmath>

#include <gtest/gtest.h>

#include "navbus/core/filter/integrated_filter.hpp"
#include "navbus/core/filter/pseudorange_error_slots.hpp"
#include "navbus/sim/constellation.hpp"

namespace earth = navbus::core::earth;
namespace layout = navbus::core::layout;
using navbus::core::PseudorangeErrorSlots;

namespace {
constexpr int kFirstRangeError = layout::kPseudorangeError.index;

navbus::core::NavState restingReceiver() {
  navbus::core::NavState s;
  s.time_ns = 1'400'000'000'000'000'000;
  s.position = {36.5 * M_PI / 180, 127.5 * M_PI / 180, 100.0};
  return s;
}

/// The visible satellites with noise-free pseudoranges from `truth`, clock bias 0, plus
/// `extra_m` on the first one.
std::vector<navbus::core::SatelliteObservation> satellitesWithRangeError(
    const navbus::core::NavState& truth, double extra_m) {
  navbus::sim::Constellation c(navbus::sim::ConstellationConfig{});
  const Eigen::Vector3d r = earth::geodeticToEcef(truth.position);
  std::vector<navbus::core::SatelliteObservation> out;
  for (const auto& k : c.almanac()) {
    const auto st = c.state(k.sv_id, 1.4e9);
    if ((st.pos_ecef_m - r).normalized().dot(r.normalized()) <= 0.1) continue;
    navbus::core::SatelliteObservation o;
    o.sv_id = k.sv_id;
    o.sat_pos_ecef_m = st.pos_ecef_m;
    o.sat_vel_ecef_mps = st.vel_ecef_mps;
    const auto p = navbus::core::predictRange(truth, 0.0, 0.0, o);
    o.pseudorange_m = p.pseudorange_m + (out.empty() ? extra_m : 0.0);
    o.pseudorange_rate_mps = p.pseudorange_rate_mps;
    o.pseudorange_sigma_m = 0.5;
    out.push_back(o);
  }
  return out;
}

navbus::core::FilterTuning rangeErrorTuning() {
  navbus::core::FilterTuning t;
  t.pos_sigma_m = 10.0;
  t.clock_bias_sigma_m = 10.0;
  t.gate_sigma = 0.0;
  t.pseudorange_error_sigma_m = 5.0;
  t.pseudorange_error_correlation_time_s = 100.0;
  return t;
}

navbus::core::StateMask rangeErrorMask() {
  using namespace layout;
  return navbus::core::maskOf(
      {kPos, kVel, kAtt, kAccelBias, kGyroBias, kClockBias, kClockDrift, kPseudorangeError});
}
}  // namespace

TEST(PseudorangeErrorSlots, SatellitesTakeFreeStatesAndGiveThemUpWhenTheyGo) {
  PseudorangeErrorSlots slots;
  auto a = slots.assign({5, 9, 12});
  EXPECT_EQ(a.state_index,
            (std::vector<int>{kFirstRangeError, kFirstRangeError + 1, kFirstRangeError + 2}));
  EXPECT_EQ(a.fresh, a.state_index);
  // 9 is gone: its state is free for 20, the others keep theirs and are not fresh.
  a = slots.assign({12, 20, 5});
  EXPECT_EQ(a.state_index,
            (std::vector<int>{kFirstRangeError + 2, kFirstRangeError + 1, kFirstRangeError}));
  EXPECT_EQ(a.fresh, (std::vector<int>{kFirstRangeError + 1}));
  // 9 comes back: a new satellite to the slots, from the prior.
  a = slots.assign({12, 20, 5, 9});
  EXPECT_EQ(a.fresh, (std::vector<int>{kFirstRangeError + 3}));
  EXPECT_EQ(slots.unmodelled(), 0u);
  // More satellites than states: the rest are counted, not modelled.
  std::vector<int> many;
  for (int sv = 1; sv <= PseudorangeErrorSlots::kSlots + 3; ++sv) many.push_back(sv);
  a = slots.assign(many);
  EXPECT_EQ(std::count(a.state_index.begin(), a.state_index.end(), -1), 3);
  EXPECT_EQ(slots.unmodelled(), 3u);
}

TEST(PseudorangeErrorSlots, ASecondReceiversClockLeavesTheLastTwoStatesAlone) {
  // Given slots beside a second receiver's clock, when more satellites than states come, then
  // none takes layout::kSecondClockBias or kSecondClockDrift (two more are left unmodelled), a
  // same satellite of both receivers takes one state, and a correction of the clock's states
  // changes no satellite's estimate.
  PseudorangeErrorSlots slots;
  slots.leaveStatesToSecondClock(true);
  EXPECT_EQ(slots.slotsInUse(), PseudorangeErrorSlots::kSlots - 2);
  std::vector<int> many;
  for (int sv = 1; sv <= PseudorangeErrorSlots::kSlots; ++sv) many.push_back(sv);
  many.push_back(1);  // the second receiver's satellite 1
  const auto& a = slots.assign(many);
  EXPECT_EQ(std::count(a.state_index.begin(), a.state_index.end(), -1), 2);
  for (const int state : a.state_index) {
    EXPECT_NE(state, layout::kSecondClockBias.index);
    EXPECT_NE(state, layout::kSecondClockDrift.index);
  }
  EXPECT_EQ(a.state_index.front(), a.state_index.back());
  PseudorangeErrorSlots::Errors dx = PseudorangeErrorSlots::Errors::Zero();
  dx.tail<2>().setConstant(5.0);
  slots.correct(dx);
  for (int i = 0; i < PseudorangeErrorSlots::kSlots; ++i)
    EXPECT_EQ(slots.estimate(layout::kPseudorangeError.index + i), 0.0);
}

TEST(PseudorangeErrorStates, EachSatellitesRangeRowReachesItsOwnStateOnly) {
  // An 8 m error on one satellite gives its state an estimate; in the next epoch each
  // satellite's range row has 1 in its own state's column of H and 0 in the others', and the
  // rate rows none.
  const navbus::core::NavState truth = restingReceiver();
  const auto sats = satellitesWithRangeError(truth, 8.0);
  ASSERT_GE(sats.size(), 5u);
  navbus::core::IntegratedFilter f;
  f.initialize(truth, 0.0, 0.0, rangeErrorTuning(), rangeErrorMask());
  f.update(sats);
  const auto& held = f.pseudorangeErrors().satellites();
  const int state = kFirstRangeError;  // the first satellite took the first state
  ASSERT_EQ(held[0], sats[0].sv_id);
  const double estimate = f.pseudorangeErrors().estimate(state);
  EXPECT_GT(estimate, 0.5);  // part of the 8 m (the rest goes to position and clock)
  f.update(sats);
  const auto& d = f.lastEpoch();
  for (std::size_t i = 0; i < sats.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(2 * i);
    const int s = kFirstRangeError + static_cast<int>(i);
    EXPECT_DOUBLE_EQ(d.h(row, s), 1.0) << "satellite " << sats[i].sv_id;
    EXPECT_DOUBLE_EQ(d.h(row + 1, s), 0.0) << "the rate row does not see the range error";
    for (int other = kFirstRangeError; other < layout::kPseudorangeError.end(); ++other) {
      if (other != s) {
        EXPECT_DOUBLE_EQ(d.h(row, other), 0.0);
      }
    }
  }
}

TEST(PseudorangeErrorStates, TheInnovationMovesOneForOneWithTheEstimate) {
  // The numerical difference: the same epoch processed by two filters whose only difference
  // is the first satellite's estimated error (learned from a +8 m and a +10 m range): the
  // innovations of that row differ by the estimates' difference, every other row's by the
  // position and clock estimates' share only.
  const navbus::core::NavState truth = restingReceiver();
  navbus::core::IntegratedFilter a, b;
  a.initialize(truth, 0.0, 0.0, rangeErrorTuning(), rangeErrorMask());
  b.initialize(truth, 0.0, 0.0, rangeErrorTuning(), rangeErrorMask());
  a.update(satellitesWithRangeError(truth, 8.0));
  b.update(satellitesWithRangeError(truth, 10.0));
  const auto sats = satellitesWithRangeError(truth, 0.0);
  const auto innovation_without_error = [&](const navbus::core::IntegratedFilter& f,
                                            std::size_t i) {
    return navbus::core::predictRange(f.state(), f.clockBias(), f.clockDrift(), sats[i])
               .pseudorange_m -
           sats[i].pseudorange_m;
  };
  const double ea = a.pseudorangeErrors().estimate(kFirstRangeError);
  const double eb = b.pseudorangeErrors().estimate(kFirstRangeError);
  const double za = innovation_without_error(a, 0);
  const double zb = innovation_without_error(b, 0);
  a.update(sats);
  b.update(sats);
  EXPECT_NEAR(a.lastEpoch().innovation[0] - za, ea, 1e-9);
  EXPECT_NEAR(b.lastEpoch().innovation[0] - zb, eb, 1e-9);
  EXPECT_GT(std::abs(eb - ea), 0.1);
}

TEST(PseudorangeErrorStates, DecayAsAGaussMarkovProcessAndKeepTheirStationaryVariance) {
  // Phi's diagonal element exp(-dt / tau), Q = sigma^2 (1 - exp(-2 dt / tau)): over T the
  // estimate falls by exp(-T / tau), a held state's variance relaxes towards sigma^2 by the
  // same law, and a free state stays at sigma^2.
  const navbus::core::NavState truth = restingReceiver();
  const navbus::core::FilterTuning t = rangeErrorTuning();
  navbus::core::IntegratedFilter f;
  f.initialize(truth, 0.0, 0.0, t, rangeErrorMask());
  const auto sats = satellitesWithRangeError(truth, 8.0);
  f.update(sats);
  const int held = kFirstRangeError;
  const int free = kFirstRangeError + static_cast<int>(sats.size());
  const double e0 = f.pseudorangeErrors().estimate(held);
  const double v0 = f.covariance()(held, held);
  const double sigma2 = t.pseudorange_error_sigma_m * t.pseudorange_error_sigma_m;
  ASSERT_LT(v0, 0.9 * sigma2);
  navbus::core::ImuIncrement inc;
  inc.interval_s = 0.01;
  const int steps = 2000;  // 20 s
  for (int k = 0; k < steps; ++k) {
    inc.time_ns = truth.time_ns + static_cast<std::int64_t>(k + 1) * 10'000'000;
    f.propagate(inc);
  }
  const double decay = std::exp(-steps * inc.interval_s / t.pseudorange_error_correlation_time_s);
  EXPECT_NEAR(f.pseudorangeErrors().estimate(held), e0 * decay, 1e-12 * std::abs(e0));
  EXPECT_NEAR(f.covariance()(held, held), decay * decay * v0 + sigma2 * (1.0 - decay * decay),
              1e-9 * sigma2);
  EXPECT_NEAR(f.covariance()(free, free), sigma2, 1e-9 * sigma2);
}

TEST(PseudorangeErrorStates, AReceiverClockShiftedByItsJumpLeavesTheJumpedRangesUnsurprising) {
  // Given a filter at the truth with clock 0, and the receiver's clock jumping 1 ms (every
  // pseudorange + 299.8 km): shifted by the jump (IntegratedFilter::shiftClock, the
  // cross-receiver test's command), its clock estimate is the jump, its clock variance grew by
  // the jump's sigma^2, and the jumped epoch's innovations are those of an epoch without a
  // jump; unshifted, every innovation carries the jump.
  const navbus::core::NavState truth = restingReceiver();
  const double jump_m = 1e-3 * earth::kSpeedOfLight_mps;
  auto jumped = satellitesWithRangeError(truth, 0.0);
  for (auto& s : jumped) s.pseudorange_m += jump_m;
  navbus::core::IntegratedFilter shifted, unshifted;
  shifted.initialize(truth, 0.0, 0.0, rangeErrorTuning(), rangeErrorMask());
  unshifted.initialize(truth, 0.0, 0.0, rangeErrorTuning(), rangeErrorMask());
  const int clock = layout::kClockBias.index;
  const double variance_before = shifted.covariance()(clock, clock);
  shifted.shiftClock(jump_m, 16.0);
  EXPECT_DOUBLE_EQ(shifted.clockBias(), jump_m);
  EXPECT_NEAR(shifted.covariance()(clock, clock), variance_before + 256.0, 1e-9);
  shifted.update(jumped);
  unshifted.update(jumped);
  const auto& with = shifted.lastEpoch().innovation;
  const auto& without = unshifted.lastEpoch().innovation;
  ASSERT_GT(with.size(), 4);
  for (Eigen::Index i = 0; i < with.size(); ++i) {
    EXPECT_LT(std::abs(with[i]), 1e-3) << "row " << i;
  }
  EXPECT_GT(std::abs(without[0]), 0.99 * jump_m);
}
