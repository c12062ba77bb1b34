// Packs the simulator's IMU increments and raw samples into blocks for fast pacing: the same
// increments and raw samples in fewer DDS samples (ImuIncrementBlock, larger ImuRawBlocks).
// Per-sample costs of DDS (serialization, sends, acknowledgments, wake-ups in every reader),
// not the data, bound the rate at which a replay runs; latency does not matter there.
#pragma once

#include <cstddef>
#include <cstdint>

#include <navbus_idl/Imu.h>

#include "navbus/bus/streams.hpp"

namespace navbus::sensor_sim {

class ImuBlockBatcher {
 public:
  /// The IDL bounds of ImuIncrementBlock.increments and ImuRawBlock.samples.
  static constexpr std::size_t kMaxIncrements = bus::kMaxIncrementsPerBlock;
  static constexpr std::size_t kMaxRawSamples = 256;

  /// `increments_per_block` in 1..kMaxIncrements.
  explicit ImuBlockBatcher(std::size_t increments_per_block);

  /// Adds one increment (consecutive, one sensor).
  void addIncrement(const navbus::ImuIncrement& increment);
  /// The increment block holds its length: write takeIncrements() (and takeRaw(), so that
  /// both blocks cover the same frames).
  bool full() const { return increments_.increments().size() >= increments_per_block_; }
  /// Appends a raw block's samples to the pending raw block. False, adding nothing, when they
  /// do not continue it (another sensor or rate, a gap in time: a start more than half a
  /// period off the block's sample times, or beyond kMaxRawSamples):
  /// write takeRaw() first, then add again.
  bool addRaw(const navbus::ImuRawBlock& raw);

  bool hasIncrements() const { return !increments_.increments().empty(); }
  bool hasRaw() const { return !raw_.samples().empty(); }
  /// The pending block, numbered (1 for the first block, +1 per block), leaving none pending.
  navbus::ImuIncrementBlock takeIncrements();
  navbus::ImuRawBlock takeRaw();

 private:
  std::size_t increments_per_block_;
  navbus::ImuIncrementBlock increments_;
  navbus::ImuRawBlock raw_;
  std::uint64_t increment_blocks_{0};
  std::uint64_t raw_blocks_{0};
};

}  // namespace navbus::sensor_sim
