// Sampled IMU output (specific force and angular rate at instants) turned into the increments
// navbus's IMU topic carries: the integral over each interval between consecutive samples, by
// the trapezoidal rule, time-stamped at the interval's end, grouped into blocks for the
// recording. The first sample only opens the first interval.
#pragma once

#include <cstdint>
#include <vector>

#include <navbus_idl/Imu.h>

#include "navbus/importers/imu_csv.hpp"

namespace navbus::importers {

std::vector<navbus::ImuIncrement> incrementsFromSamples(const std::vector<ImuSample>& samples,
                                                        std::uint32_t sensor_id);

/// Consecutive increments in blocks spanning at most `block_s` of data (and at most the
/// topic's 64 elements), numbered from 1.
std::vector<navbus::ImuIncrementBlock> blocksOf(const std::vector<navbus::ImuIncrement>& increments,
                                                double block_s);

}  // namespace navbus::importers
