// Chi-square tail probabilities for integer degrees of freedom, in closed form (no series
// truncation): used to state what a GLR threshold means and to compare statistics of
// hypotheses with different numbers of parameters.
#pragma once

namespace navbus::core {

/// P(X >= x) for X ~ chi-square with `dof` >= 1 degrees of freedom; 1 for x <= 0.
///   even dof: exp(-x/2) sum_{i < dof/2} (x/2)^i / i!
///   odd dof:  erfc(sqrt(x/2)) + exp(-x/2) sum_{i < (dof-1)/2} (x/2)^(i+1/2) / Gamma(i+3/2)
double chiSquareSurvival(double x, int dof);

/// -log10 of chiSquareSurvival, computed without underflow for large x (the significance of a
/// statistic: 6 means a one-in-a-million event under the no-fault hypothesis).
double chiSquareSignificance(double x, int dof);

/// The value a chi-square variable with `dof` >= 1 degrees of freedom exceeds with probability
/// p in (0, 1) (Boost.Math's inverse of chiSquareSurvival).
double chiSquareQuantile(double p, int dof);

}  // namespace navbus::core
