// Overlapping Allan deviation of a rate signal (IEEE Std 952 characterization of inertial
// sensor noise).
#pragma once

#include <vector>

namespace navbus::core {

/// Overlapping Allan deviation of `rate` sampled every `dt` seconds, at the averaging time
/// m * dt. Returns 0 when the series is shorter than 2m + 1 samples.
double allanDeviation(const std::vector<double>& rate, double dt, std::size_t m);

}  // namespace navbus::core
