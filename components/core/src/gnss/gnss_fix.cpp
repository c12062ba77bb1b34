#include "navbus/core/gnss/gnss_fix.hpp"

#include <cmath>

#include <Eigen/Dense>

#include "navbus/core/math/earth.hpp"

namespace navbus::core {

LeastSquaresFix leastSquaresFix(const std::vector<RangeObservation>& obs,
                                const Eigen::Vector3d& initial) {
  LeastSquaresFix fix;
  const auto m = static_cast<Eigen::Index>(obs.size());
  if (m < 4) return fix;
  Eigen::Vector4d x(initial.x(), initial.y(), initial.z(), 0.0);
  Eigen::MatrixX4d H(m, 4);
  Eigen::VectorXd dz(m);
  for (fix.iterations = 1; fix.iterations <= 20; ++fix.iterations) {
    for (Eigen::Index i = 0; i < m; ++i) {
      const Eigen::Vector3d d = obs[static_cast<std::size_t>(i)].sat_pos_ecef_m - x.head<3>();
      const double range = d.norm();
      H.row(i) << -d.transpose() / range, 1.0;
      dz[i] = obs[static_cast<std::size_t>(i)].pseudorange_m - (range + x[3]);
    }
    const Eigen::Vector4d step = (H.transpose() * H).ldlt().solve(H.transpose() * dz);
    x += step;
    if (step.head<3>().norm() < 1e-4) {
      fix.valid = true;
      break;
    }
  }
  if (!fix.valid) return fix;
  // Velocity and drift: rate_i = -los_i . (v_r - v_s) ... linear in (v_r, drift) with the same H.
  Eigen::VectorXd rz(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto& o = obs[static_cast<std::size_t>(i)];
    const Eigen::Vector3d los = (o.sat_pos_ecef_m - x.head<3>()).normalized();
    rz[i] = o.pseudorange_rate_mps - los.dot(o.sat_vel_ecef_mps);
  }
  const Eigen::Matrix4d N_inv = (H.transpose() * H).inverse();
  const Eigen::Vector4d v = N_inv * H.transpose() * rz;
  fix.pos_ecef_m = x.head<3>();
  fix.clock_bias_m = x[3];
  fix.vel_ecef_mps = v.head<3>();
  fix.clock_drift_mps = v[3];
  // Dilution of precision; horizontal and vertical in the local NED frame.
  const earth::Geodetic g = earth::ecefToGeodetic(fix.pos_ecef_m);
  const Eigen::Matrix3d C_e_n = earth::C_n_e(g.latitude_rad, g.longitude_rad).transpose();
  const Eigen::Matrix3d Q_n = C_e_n * N_inv.topLeftCorner<3, 3>() * C_e_n.transpose();
  fix.gdop = std::sqrt(N_inv.trace());
  fix.pdop = std::sqrt(N_inv.topLeftCorner<3, 3>().trace());
  fix.hdop = std::sqrt(Q_n(0, 0) + Q_n(1, 1));
  fix.vdop = std::sqrt(Q_n(2, 2));
  fix.tdop = std::sqrt(N_inv(3, 3));
  return fix;
}

}  // namespace navbus::core
