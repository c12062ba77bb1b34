// Master fusion of the federated filter (seed 001 eqs. 28-29):
//   P_f^-1 = sum_i P_i^-1,   P_f^-1 x_f = sum_i P_i^-1 x_i,
// over a leading block of the state (the states every local filter shares).
#pragma once

#include <Eigen/Core>

#include "navbus/core/filter/error_state.hpp"

namespace navbus::core {

template <int N>
struct FusedEstimate {
  Eigen::Matrix<double, N, 1> x;
  Eigen::Matrix<double, N, N> P;
};

/// Fuses two local estimates of the leading N states. Each inverse is taken on the matrix
/// scaled to unit diagonal (variances here span 1e-15 .. 1e3), so that the conditioning is that
/// of the correlations, not of the units.
template <int N>
FusedEstimate<N> fuseInformation(const ErrorState& a, const ErrorState& b) {
  using Mat = Eigen::Matrix<double, N, N>;
  using Vec = Eigen::Matrix<double, N, 1>;
  auto information = [](const Mat& P) {
    const Vec s = P.diagonal().cwiseSqrt().cwiseInverse();
    const Mat C = s.asDiagonal() * P * s.asDiagonal();
    return Mat(s.asDiagonal() * C.ldlt().solve(Mat::Identity()) * s.asDiagonal());
  };
  const Mat Pa = a.P().template topLeftCorner<N, N>();
  const Mat Pb = b.P().template topLeftCorner<N, N>();
  const Mat Ya = information(Pa);
  const Mat Yb = information(Pb);
  const Mat Y = Ya + Yb;
  const Vec y = Ya * a.x().template head<N>() + Yb * b.x().template head<N>();
  FusedEstimate<N> out;
  out.P = information(Y);
  out.P = 0.5 * (out.P + out.P.transpose());
  out.x = out.P * y;
  return out;
}

}  // namespace navbus::core
