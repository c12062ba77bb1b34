#include "navbus/core/ins/gap_bridge.hpp"

#include <algorithm>
#include <cmath>

namespace navbus::core {

std::vector<ImuIncrement> heldIncrements(const ImuIncrement& last, std::int64_t from_ns,
                                         std::int64_t to_ns) {
  std::vector<ImuIncrement> out;
  const auto step_ns = static_cast<std::int64_t>(std::llround(last.interval_s * 1e9));
  if (step_ns <= 0 || to_ns <= from_ns) return out;
  const Eigen::Vector3d specific_force = last.delta_vel_b_mps / last.interval_s;
  const Eigen::Vector3d rate = last.delta_angle_b_rad / last.interval_s;
  out.reserve(static_cast<std::size_t>((to_ns - from_ns) / step_ns + 1));
  for (std::int64_t t = from_ns; t < to_ns;) {
    const std::int64_t end = std::min(t + step_ns, to_ns);
    ImuIncrement inc;
    inc.time_ns = end;
    inc.interval_s = 1e-9 * static_cast<double>(end - t);
    inc.delta_vel_b_mps = specific_force * inc.interval_s;
    inc.delta_angle_b_rad = rate * inc.interval_s;
    out.push_back(inc);
    t = end;
  }
  return out;
}

GapVariances gapVariances(const GapBridgeConfig& c, double gap_s, bool bridged, double speed_mps) {
  const double t = gap_s;
  const double drift_m = c.accel_sigma_mps2 * t * t / 2.0;
  const double position_m = bridged ? drift_m : speed_mps * t + drift_m;
  return {position_m * position_m, std::pow(c.accel_sigma_mps2 * t, 2),
          std::pow(c.rate_sigma_radps * t, 2)};
}

}  // namespace navbus::core
