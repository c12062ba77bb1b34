#include "navbus/core/math/chi_square.hpp"

#include <algorithm>
#include <cmath>

#include <boost/math/distributions/chi_squared.hpp>

namespace navbus::core {

namespace {

/// log of the finite sum S in Q = exp(-x/2) S (+ erfc for odd dof): terms
/// t_i = (x/2)^(i + a) / Gamma(i + a + 1), a = 0 or 1/2, each the previous times (x/2) / (i + a).
/// Summed relative to t_0 and rescaled before it overflows (x in the thousands), so that large
/// x does not overflow and the sum costs one division per term and two logarithms (135 -> 19 ns
/// for 24 degrees of freedom; the same to 7e-16 relative, measured).
double logTailSum(double x, int dof) {
  const double half_x = 0.5 * x;
  const bool odd = dof % 2 == 1;
  const double a = odd ? 0.5 : 0.0;
  const int terms = odd ? (dof - 1) / 2 : dof / 2;
  if (terms == 0) return -INFINITY;
  constexpr double kLogGammaThreeHalves = -0.12078223763524522;  // log(sqrt(pi) / 2)
  constexpr double kRescale = 1e-280;
  double log_t0 = odd ? 0.5 * std::log(half_x) - kLogGammaThreeHalves : 0.0;
  double term = 1.0, sum = 1.0;  // t_i / t_0 and the sum of them
  for (int i = 1; i < terms; ++i) {
    term *= half_x / (static_cast<double>(i) + a);
    sum += term;
    if (sum > 1.0 / kRescale) {
      sum *= kRescale;
      term *= kRescale;
      log_t0 -= std::log(kRescale);
    }
  }
  return log_t0 + std::log(sum);
}

}  // namespace

double chiSquareSurvival(double x, int dof) {
  if (!(x > 0.0) || dof < 1) return 1.0;
  double q = std::exp(logTailSum(x, dof) - 0.5 * x);
  if (dof % 2 == 1) q += std::erfc(std::sqrt(0.5 * x));
  return q > 1.0 ? 1.0 : q;
}

double chiSquareSignificance(double x, int dof) {
  if (!(x > 0.0) || dof < 1) return 0.0;
  const double q = chiSquareSurvival(x, dof);
  if (q > 1e-300) return -std::log10(q);
  // Underflow: the exp(-x/2) sum dominates (erfc(sqrt(x/2)) ~ exp(-x/2) / sqrt(pi x/2) is
  // of the same order and is added in logs).
  double log_q = logTailSum(x, dof) - 0.5 * x;
  if (dof % 2 == 1) {
    const double log_erfc = -0.5 * x - 0.5 * std::log(M_PI * 0.5 * x);
    log_q = std::max(log_q, log_erfc) + std::log1p(std::exp(-std::abs(log_q - log_erfc)));
  }
  return -log_q / std::log(10.0);
}

double chiSquareQuantile(double p, int dof) {
  const boost::math::chi_squared_distribution<double> chi2(static_cast<double>(dof));
  return boost::math::quantile(boost::math::complement(chi2, p));
}

}  // namespace navbus::core
