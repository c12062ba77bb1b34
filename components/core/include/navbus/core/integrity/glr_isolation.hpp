// Isolation among the GLR's hypotheses (seed 000 eqs. 14-16) at one onset of the window: INS
// against GNSS first (the group whose statistic is least likely under no fault, given its
// number of identifiable directions), then which axis or which satellite, by projecting the
// window's sums onto single directions (f* = T^T f, R* = T^T R T); directions that explain the
// data about as well as the best, or whose signatures are nearly collinear with its, are
// reported as ambiguous instead of picking one.
#pragma once

#include "navbus/core/integrity/glr_types.hpp"
#include "navbus/core/integrity/glr_window.hpp"

namespace navbus::core {

/// Fills the isolation fields of `r` (from onset_epochs_ago on, GlrResult) for the onset of the
/// given age, which must be in the window.
void isolateOnset(const GlrWindow& window, const GlrConfig& config, int onset_age, GlrResult& r);

}  // namespace navbus::core
