#include "navbus/core/math/allan.hpp"

#include <cmath>

namespace navbus::core {

double allanDeviation(const std::vector<double>& rate, double dt, std::size_t m) {
  const std::size_t n = rate.size();
  if (m == 0 || n < 2 * m + 1) return 0.0;
  // Integrated signal theta_k = dt * sum_{i<k} rate_i; sigma^2 = sum (theta_{k+2m} - 2 theta_{k+m}
  // + theta_k)^2 / (2 tau^2 (N - 2m)), over every k (overlapping estimator).
  std::vector<double> theta(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) theta[i + 1] = theta[i] + rate[i] * dt;
  const double tau = static_cast<double>(m) * dt;
  double sum = 0.0;
  const std::size_t count = n + 1 - 2 * m;
  for (std::size_t k = 0; k < count; ++k) {
    const double d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
    sum += d * d;
  }
  return std::sqrt(sum / (2.0 * tau * tau * static_cast<double>(count)));
}

}  // namespace navbus::core
