#include "navbus/core/math/chi_square.hpp"

#include <algorithm>
#include <cmath>

#include <boost/math/distributions/chi_squared.hpp>

namespace navbus::core {

namespace {

/// log of the finite sum S in Q = exp(-x/2) S (+ erfc for odd dof), evaluated in logs so that
/// large x does not underflow: terms t_i = (x/2)^(i + a) / Gamma(i + a + 1), a = 0 or 1/2.
double logTailSum(double x, int dof) {
  const double half_x = 0.5 * x;
  const double a = (dof % 2 == 0) ? 0.0 : 0.5;
  const int terms = (dof % 2 == 0) ? dof / 2 : (dof - 1) / 2;
  if (terms == 0) return -INFINITY;
  double log_term = a * std::log(half_x) - std::lgamma(a + 1.0);
  double max_log = log_term;
  double sum_scaled = 1.0;  // sum of exp(log_term_i - max_log), rescaled as the maximum moves
  for (int i = 1; i < terms; ++i) {
    log_term += std::log(half_x) - std::log(static_cast<double>(i) + a);
    if (log_term > max_log) {
      sum_scaled = sum_scaled * std::exp(max_log - log_term) + 1.0;
      max_log = log_term;
    } else {
      sum_scaled += std::exp(log_term - max_log);
    }
  }
  return max_log + std::log(sum_scaled);
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
