#include "navbus/core/filter/static_receiver_filter.hpp"

#include <cmath>

#include "navbus/core/math/earth.hpp"
#include "navbus/core/math/sparse_rows.hpp"

namespace navbus::core {

using namespace layout;

void StaticReceiverFilter::initialize(const Eigen::Vector3d& pos_ecef_m, double clock_bias_m,
                                      double time_s, const StaticReceiverTuning& tuning) {
  tuning_ = tuning;
  time_s_ = time_s;
  state_ = NavState{};
  state_.position = earth::ecefToGeodetic(pos_ecef_m);
  clock_bias_m_ = clock_bias_m;
  clock_drift_mps_ = 0.0;
  StateMatrix P0 = StateMatrix::Zero();
  P0.block<3, 3>(kPos.index, kPos.index)
      .diagonal()
      .setConstant(tuning.pos_sigma_m * tuning.pos_sigma_m);
  P0(kClockBias.index, kClockBias.index) = tuning.clock_bias_sigma_m * tuning.clock_bias_sigma_m;
  P0(kClockDrift.index, kClockDrift.index) =
      tuning.clock_drift_sigma_mps * tuning.clock_drift_sigma_mps;
  error_.initialize(P0, maskOf({kPos, kClockBias, kClockDrift}));
  initialized_ = true;
}

void StaticReceiverFilter::propagate(double dt_s) {
  // Position constant; clock bias integrates the drift (seed 000 eq. 3).
  StateMatrix Phi = StateMatrix::Identity();
  Phi(kClockBias.index, kClockDrift.index) = dt_s;
  StateVector q = StateVector::Zero();
  q[kClockBias.index] =
      tuning_.clock_bias_noise_m_per_sqrts * tuning_.clock_bias_noise_m_per_sqrts * dt_s;
  q[kClockDrift.index] =
      tuning_.clock_drift_noise_mps_per_sqrts * tuning_.clock_drift_noise_mps_per_sqrts * dt_s;
  error_.predict(Phi, q);
  clock_bias_m_ += clock_drift_mps_ * dt_s;
  phi_ = SparseRows<layout::kSize>(Phi, transitionPattern()).times(phi_);
}

const EpochDiagnostics& StaticReceiverFilter::update(
    double time_s, const std::vector<SatelliteObservation>& sats) {
  propagate(time_s - time_s_);
  time_s_ = time_s;
  const auto m = static_cast<Eigen::Index>(sats.size());
  EpochDiagnostics& d = last_epoch_;
  d.sv_ids.clear();
  d.is_rate.assign(sats.size(), false);
  d.used.clear();
  d.test_ratio.clear();
  d.innovation.resize(m);
  d.h.resize(m, kSize);
  Eigen::VectorXd r(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const SatelliteObservation& sat = sats[static_cast<std::size_t>(i)];
    const RangePrediction p = predictRange(state_, clock_bias_m_, clock_drift_mps_, sat);
    d.innovation[i] = p.pseudorange_m - sat.pseudorange_m;  // predicted minus measured
    d.h.row(i) = p.h_range;
    r[i] = sat.pseudorange_sigma_m * sat.pseudorange_sigma_m;
    d.sv_ids.push_back(sat.sv_id);
  }
  applied_gain_.prepare(d, error_.P());
  d.innovation_cov.diagonal() += r;
  d.phi = phi_;
  for (Eigen::Index i = 0; i < m; ++i) {
    ScalarUpdateResult res;
    if (sats[static_cast<std::size_t>(i)].use_range) {
      AidingMeasurement<1> one;
      one.z[0] = d.innovation[i];
      one.h = d.h.row(i);
      one.r(0, 0) = r[i];
      res = error_.update(one, tuning_.gate_sigma)[0];
    } else {
      // Monitored only: the row's innovation test, no update.
      const double gate = tuning_.gate_sigma > 0.0 ? tuning_.gate_sigma : 1.0;
      res.test_ratio = d.innovation[i] * d.innovation[i] / (gate * gate * d.innovation_cov(i, i));
    }
    d.test_ratio.push_back(res.test_ratio);
    d.used.push_back(res.accepted);
  }
  applied_gain_.compute(d);
  feedback();
  phi_.setIdentity();
  return d;
}

void StaticReceiverFilter::feedback() {
  const StateVector& dx = error_.x();
  state_.position = earth::offsetNed(state_.position, -dx.segment<3>(kPos.index));
  clock_bias_m_ -= dx[kClockBias.index];
  clock_drift_mps_ -= dx[kClockDrift.index];
  error_.x().setZero();
}

Eigen::Vector3d StaticReceiverFilter::positionEcef() const {
  return earth::geodeticToEcef(state_.position);
}

Eigen::Matrix3d StaticReceiverFilter::positionCovarianceNed() const {
  return error_.P().block<3, 3>(kPos.index, kPos.index);
}

}  // namespace navbus::core
