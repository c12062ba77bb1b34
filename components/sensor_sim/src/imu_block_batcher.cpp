#include "navbus/sensor_sim/imu_block_batcher.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>

namespace navbus::sensor_sim {

ImuBlockBatcher::ImuBlockBatcher(std::size_t increments_per_block)
    : increments_per_block_(increments_per_block) {
  if (increments_per_block < 1 || increments_per_block > kMaxIncrements) {
    throw std::invalid_argument("increments per block = " + std::to_string(increments_per_block) +
                                " is not in 1.." + std::to_string(kMaxIncrements));
  }
  increments_.increments().reserve(increments_per_block);
}

void ImuBlockBatcher::addIncrement(const navbus::ImuIncrement& increment) {
  if (!hasIncrements()) increments_.sensor_id(increment.sensor_id());
  increments_.increments().push_back(increment);
}

bool ImuBlockBatcher::addRaw(const navbus::ImuRawBlock& raw) {
  if (!hasRaw()) {
    if (raw.samples().size() > kMaxRawSamples) return false;
    raw_.sensor_id(raw.sensor_id());
    raw_.first_sample_time_gps_ns(raw.first_sample_time_gps_ns());
    raw_.sample_period_ns(raw.sample_period_ns());
  } else {
    const std::size_t n = raw_.samples().size();
    // The period is whole nanoseconds (416667 ns at 2400 Hz), the samples' times are not: a
    // continuation starts within half a period of where the block's times put it, a gap of a
    // sample or more does not.
    const auto next_ns =
        static_cast<std::int64_t>(raw_.first_sample_time_gps_ns() + n * raw_.sample_period_ns());
    const std::int64_t offset_ns =
        static_cast<std::int64_t>(raw.first_sample_time_gps_ns()) - next_ns;
    if (raw.sensor_id() != raw_.sensor_id() || raw.sample_period_ns() != raw_.sample_period_ns() ||
        2 * std::llabs(offset_ns) >= static_cast<std::int64_t>(raw_.sample_period_ns()) ||
        n + raw.samples().size() > kMaxRawSamples) {
      return false;
    }
  }
  raw_.samples().insert(raw_.samples().end(), raw.samples().begin(), raw.samples().end());
  return true;
}

navbus::ImuIncrementBlock ImuBlockBatcher::takeIncrements() {
  increments_.seq(++increment_blocks_);
  navbus::ImuIncrementBlock out = std::move(increments_);
  increments_ = navbus::ImuIncrementBlock();
  increments_.increments().reserve(increments_per_block_);
  return out;
}

navbus::ImuRawBlock ImuBlockBatcher::takeRaw() {
  raw_.seq(++raw_blocks_);
  navbus::ImuRawBlock out = std::move(raw_);
  raw_ = navbus::ImuRawBlock();
  return out;
}

}  // namespace navbus::sensor_sim
