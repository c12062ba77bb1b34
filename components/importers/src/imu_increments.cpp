#include "navbus/importers/imu_increments.hpp"

#include <cmath>

#include "navbus/bus/streams.hpp"

namespace navbus::importers {

namespace {
/// Increments per imported block: 0.64 s of a 100 Hz IMU, within the topic's bound.
constexpr std::size_t kMaxBlockElements = 64;
static_assert(kMaxBlockElements <= bus::kMaxIncrementsPerBlock);
}  // namespace

std::vector<navbus::ImuIncrement> incrementsFromSamples(const std::vector<ImuSample>& samples,
                                                        std::uint32_t sensor_id) {
  std::vector<navbus::ImuIncrement> out;
  if (samples.size() < 2) return out;
  out.reserve(samples.size() - 1);
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const ImuSample& a = samples[k - 1];
    const ImuSample& b = samples[k];
    const std::int64_t interval_ns = b.time_gps_ns - a.time_gps_ns;
    const double dt_s = 1e-9 * static_cast<double>(interval_ns);
    // Trapezoidal rule over (t_a, t_b]: the mean of the two samples times the interval.
    const Eigen::Vector3d dv = 0.5 * (a.specific_force_s_mps2 + b.specific_force_s_mps2) * dt_s;
    const Eigen::Vector3d dtheta = 0.5 * (a.rate_s_radps + b.rate_s_radps) * dt_s;
    navbus::ImuIncrement inc;
    inc.sensor_id(sensor_id);
    inc.seq(k);
    inc.time_gps_ns(static_cast<std::uint64_t>(b.time_gps_ns));
    inc.interval_ns(static_cast<std::uint32_t>(interval_ns));
    inc.delta_vel_b_mps({dv.x(), dv.y(), dv.z()});
    inc.delta_angle_b_rad({dtheta.x(), dtheta.y(), dtheta.z()});
    inc.status_flags(0);
    out.push_back(inc);
  }
  return out;
}

std::vector<navbus::ImuIncrementBlock> blocksOf(const std::vector<navbus::ImuIncrement>& increments,
                                                double block_s) {
  std::vector<navbus::ImuIncrementBlock> out;
  const auto block_ns = std::llround(block_s * 1e9);
  std::uint64_t block_start_ns = 0;
  for (const navbus::ImuIncrement& inc : increments) {
    const bool full =
        !out.empty() && (out.back().increments().size() >= kMaxBlockElements ||
                         inc.time_gps_ns() - block_start_ns > static_cast<std::uint64_t>(block_ns));
    if (out.empty() || full) {
      navbus::ImuIncrementBlock block;
      block.sensor_id(inc.sensor_id());
      block.seq(out.size() + 1);
      out.push_back(block);
      block_start_ns = inc.time_gps_ns() - inc.interval_ns();
    }
    out.back().increments().push_back(inc);
  }
  return out;
}

}  // namespace navbus::importers
