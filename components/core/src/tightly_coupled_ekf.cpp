#include "navbus/core/tightly_coupled_ekf.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "navbus/core/rotation.hpp"

namespace navbus::core {

using namespace tc17;

void TightlyCoupledEkf::initialize(const NavState& state, double clock_bias_m,
                                   double clock_drift_mps, const TightlyCoupledConfig& config) {
  config_ = config;
  ins_ = StrapdownNed(config.gravity);
  ins_.initialize(state);
  clock_bias_m_ = clock_bias_m;
  clock_drift_mps_ = clock_drift_mps;
  accel_bias_.setZero();
  gyro_bias_.setZero();
  Vector17 sigma;
  sigma.segment<3>(kPos.index).setConstant(config.pos_sigma_m);
  sigma.segment<3>(kVel.index).setConstant(config.vel_sigma_mps);
  sigma.segment<3>(kAtt.index) << config.level_sigma_rad, config.level_sigma_rad,
      config.heading_sigma_rad;
  sigma.segment<3>(kAccelBias.index).setConstant(config.accel_bias_sigma_mps2);
  sigma.segment<3>(kGyroBias.index).setConstant(config.gyro_bias_sigma_radps);
  sigma[kClockBias.index] = config.clock_bias_sigma_m;
  sigma[kClockDrift.index] = config.clock_drift_sigma_mps;
  P_ = sigma.array().square().matrix().asDiagonal();
  phi_since_update_.setIdentity();
}

void TightlyCoupledEkf::propagate(const ImuIncrement& raw) {
  ImuIncrement inc = raw;
  inc.delta_vel_b_mps -= accel_bias_ * inc.interval_s;
  inc.delta_angle_b_rad -= gyro_bias_ * inc.interval_s;
  const double dt = inc.interval_s;
  // F at the state at the start of the interval (first-order hold of the error dynamics).
  const Matrix17 Phi =
      transitionMatrix(errorDynamics(ins_.state(), inc.delta_vel_b_mps / dt, config_.gravity), dt);
  ins_.propagate(inc);
  clock_bias_m_ += clock_drift_mps_ * dt;
  // Discrete process noise: white specific force / rate noise into velocity / attitude
  // (isotropic, so the body-to-NED rotation drops out), clock random walks (seed 000 eq. 3).
  Matrix17 Q = Matrix17::Zero();
  Q.block<3, 3>(kVel.index, kVel.index)
      .diagonal()
      .setConstant(std::pow(config_.accel_noise_mps2_per_sqrthz, 2) * dt);
  Q.block<3, 3>(kAtt.index, kAtt.index)
      .diagonal()
      .setConstant(std::pow(config_.gyro_noise_radps_per_sqrthz, 2) * dt);
  Q(kClockBias.index, kClockBias.index) = std::pow(config_.clock_bias_noise_m_per_sqrts, 2) * dt;
  Q(kClockDrift.index, kClockDrift.index) =
      std::pow(config_.clock_drift_noise_mps_per_sqrts, 2) * dt;
  P_ = Phi * P_ * Phi.transpose() + Q;
  P_ = 0.5 * (P_ + P_.transpose());
  phi_since_update_ = Phi * phi_since_update_;
}

std::vector<MeasurementReport> TightlyCoupledEkf::update(
    const std::vector<SatelliteObservation>& sats) {
  const auto m = static_cast<Eigen::Index>(2 * sats.size());
  EpochDiagnostics& d = last_epoch_;
  d.sv_ids.clear();
  d.is_rate.clear();
  d.test_ratio.clear();
  d.innovation.resize(m);
  d.h.resize(m, kSize);
  Eigen::VectorXd r(m);
  for (std::size_t i = 0; i < sats.size(); ++i) {
    const auto& sat = sats[i];
    const RangePrediction p = predictRange(ins_.state(), clock_bias_m_, clock_drift_mps_, sat);
    const auto row = static_cast<Eigen::Index>(2 * i);
    // Innovations in the error-state form z = H dx + v: predicted minus measured (seed 000 eq. 5).
    d.innovation[row] = p.pseudorange_m - sat.pseudorange_m;
    d.innovation[row + 1] = p.pseudorange_rate_mps - sat.pseudorange_rate_mps;
    d.h.row(row) = p.h_range;
    d.h.row(row + 1) = p.h_rate;
    r[row] = sat.pseudorange_sigma_m * sat.pseudorange_sigma_m;
    r[row + 1] = sat.pseudorange_rate_sigma_mps * sat.pseudorange_rate_sigma_mps;
    d.sv_ids.insert(d.sv_ids.end(), {sat.sv_id, sat.sv_id});
    d.is_rate.insert(d.is_rate.end(), {false, true});
  }
  // Batch view from the prior covariance, published for the GLR; the update itself is
  // sequential (exact for the diagonal R) so that each row can be gated on its own.
  d.innovation_cov = d.h * P_ * d.h.transpose();
  d.innovation_cov.diagonal() += r;
  d.k = P_ * d.h.transpose() * d.innovation_cov.inverse();
  d.phi = phi_since_update_;
  std::vector<MeasurementReport> reports;
  Vector17 dx = Vector17::Zero();
  for (Eigen::Index row = 0; row < m; ++row) {
    const Eigen::Matrix<double, 1, kSize> h = d.h.row(row);
    const ScalarUpdateResult res =
        scalarUpdate<kSize>(dx, P_, h, d.innovation[row], r[row], config_.gate_sigma);
    d.test_ratio.push_back(res.test_ratio);
    reports.push_back(
        {d.sv_ids[static_cast<std::size_t>(row)], d.is_rate[static_cast<std::size_t>(row)], res});
  }
  feedback(dx);
  phi_since_update_.setIdentity();
  return reports;
}

std::array<ScalarUpdateResult, 3> TightlyCoupledEkf::update(const VectorMeasurement& m) {
  // Decorrelate the rows (R = L L^T, z' = L^-1 z, H' = L^-1 H) so that scalar updates are exact.
  const Eigen::Matrix3d L = m.r.llt().matrixL();
  const Eigen::Vector3d z = L.triangularView<Eigen::Lower>().solve(m.z);
  const Eigen::Matrix<double, 3, kSize> H = L.triangularView<Eigen::Lower>().solve(m.h);
  Vector17 dx = Vector17::Zero();
  std::array<ScalarUpdateResult, 3> out;
  for (int i = 0; i < 3; ++i) {
    out[static_cast<std::size_t>(i)] =
        scalarUpdate<kSize>(dx, P_, H.row(i), z[i], 1.0, config_.gate_sigma);
  }
  feedback(dx);
  phi_since_update_.setIdentity();
  return out;
}

void TightlyCoupledEkf::feedback(const Vector17& dx) {
  // Errors are estimate minus truth: subtract them from the estimate, then the error state is 0.
  NavState s = ins_.state();
  s.position = earth::offsetNed(s.position, -dx.segment<3>(kPos.index));
  s.vel_ned_mps -= dx.segment<3>(kVel.index);
  // C_est = (I - [phi x]) C_true  =>  C_true = (I + [phi x]) C_est.
  s.q_b_to_n = (quaternionFromRotationVector(dx.segment<3>(kAtt.index)) * s.q_b_to_n).normalized();
  ins_.correct(s);
  accel_bias_ -= dx.segment<3>(kAccelBias.index);
  gyro_bias_ -= dx.segment<3>(kGyroBias.index);
  clock_bias_m_ -= dx[kClockBias.index];
  clock_drift_mps_ -= dx[kClockDrift.index];
}

}  // namespace navbus::core
