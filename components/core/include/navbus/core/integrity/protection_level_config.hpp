// The protection levels' configuration and result (glr_protection_level.hpp).
#pragma once

#include "navbus/core/integrity/glr.hpp"

namespace navbus::core {

struct IntegrityConfig {
  bool enabled{false};
  /// The fault detector the levels assume: it must be the GLR the fault manager runs on this
  /// filter (window M, threshold h and the hypotheses tested).
  GlrConfig detector;
  /// Probability that the error exceeds a level without a fault (per solution); split evenly
  /// between the horizontal and the vertical level.
  double integrity_risk{1e-7};
  /// Probability that the detector misses a fault of the minimum detectable magnitude.
  double missed_detection_probability{1e-3};
  double horizontal_alert_limit_m{40.0};  ///< [m] levels above a limit: integrity unavailable
  double vertical_alert_limit_m{50.0};    ///< [m]
};

enum class IntegrityState {
  kNotMonitored,  ///< integrity disabled, or the aiding mode has no GLR (not tightly coupled)
  kInitializing,  ///< fewer than two pseudorange epochs since the start: no fault hypothesis yet
  kAvailable,     ///< both levels within their alert limits
  kUnavailable    ///< a level exceeds its alert limit
};

/// The protection levels of one solution.
struct ProtectionLevels {
  IntegrityState state{IntegrityState::kNotMonitored};
  double horizontal_m{0.0};  ///< HPL [m]: radius in the local horizontal (N E) plane
  double vertical_m{0.0};    ///< VPL [m]: along the local vertical
};

}  // namespace navbus::core
