// Converts simulated sensor frames to IDL samples and writes them, never dropping one:
// a write that times out (a reliable reader is behind) is retried until it succeeds or the
// run is stopped.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <vector>

#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "navbus/bus/conversions.hpp"
#include "navbus/bus/participant.hpp"
#include "navbus/sensor_sim/imu_block_batcher.hpp"
#include "navbus/sensor_sim/measurement_block_batcher.hpp"
#include "navbus/sensor_sim/scenario_config.hpp"
#include "navbus/sim/samples.hpp"

namespace navbus::sensor_sim {

navbus::ImuRawBlock toIdl(const sim::RawImuBlock& block, std::uint32_t sensor_id,
                          std::uint64_t seq);
navbus::GnssObservationEpoch toIdl(const sim::GnssEpoch& epoch, std::uint32_t receiver_id,
                                   std::uint64_t seq);
navbus::GnssFix toIdl(const sim::GnssFixSample& fix, std::uint32_t receiver_id, std::uint64_t seq);
navbus::StarTrackerAttitude toIdl(const sim::StarTrackerSample& st, std::uint32_t tracker_id,
                                  std::uint64_t seq);

/// Sequence numbers of the last samples emitted per stream.
struct FrameSequence {
  std::uint64_t imu{0}, raw{0}, gnss_epochs{0}, gnss_fixes{0}, star_tracker{0};
  std::vector<std::uint64_t>
      extra_imus;  ///< per further IMU unit (SimConfig::extra_imu_sensor_ids)
  std::vector<std::uint64_t>
      extra_gnss;  ///< per further receiver (SimConfig::extra_gnss_receiver_ids)
};

/// What a FramePublisher wrote to the bus: measurements per stream and the DDS samples that
/// carried them (fewer than the measurements where they go in blocks).
struct WrittenCounts {
  std::uint64_t increments{0}, increment_samples{0};  ///< increments; samples carrying them
  std::uint64_t raw_samples{0}, raw_blocks{0};
  std::uint64_t gnss_epochs{0}, gnss_fixes{0}, star_tracker{0};
  /// Samples carrying the epochs, fixes and attitudes (one each, or blocks of them).
  std::uint64_t measurement_samples{0};

  /// DDS samples written, all streams.
  std::uint64_t samples() const { return increment_samples + raw_blocks + measurement_samples; }
  /// Measurements carried: each increment, raw sample, GNSS epoch and fix, attitude.
  std::uint64_t measurements() const {
    return increments + raw_samples + gnss_epochs + gnss_fixes + star_tracker;
  }
};

/// The bus samples of one simulator frame, in emit order (the increment first, then the raw
/// block, then the further IMU units' increments in unit order, each under its sensor id, then
/// the measurements valid at its end time, the further receivers' epochs after the scenario
/// receiver's fix), with their sequence numbers: the one definition of
/// what the simulator participant publishes, shared by FramePublisher and `navbus offline`.
/// `emit(sample)` returns false to stop; the sequence advances per sample emitted. Returns
/// false if stopped.
template <class Emit>
bool emitFrame(const sim::SensorFrame& f, const SimConfig& c, FrameSequence& seq, Emit&& emit) {
  if (!emit(bus::toIdl(f.increment, c.imu_sensor_id, seq.imu + 1))) return false;
  ++seq.imu;
  if (c.publish_raw) {
    if (!emit(toIdl(f.raw, c.imu_sensor_id, seq.raw + 1))) return false;
    ++seq.raw;
  }
  const std::size_t units = std::min(f.extra_imus.size(), c.extra_imu_sensor_ids.size());
  if (seq.extra_imus.size() < units) seq.extra_imus.resize(units, 0);
  for (std::size_t k = 0; k < units; ++k) {
    if (!emit(bus::toIdl(f.extra_imus[k].increment, c.extra_imu_sensor_ids[k],
                         seq.extra_imus[k] + 1)))
      return false;
    ++seq.extra_imus[k];
  }
  if (c.publish_gnss && f.has_gnss) {
    if (!emit(toIdl(f.gnss, c.gnss_receiver_id, seq.gnss_epochs + 1))) return false;
    ++seq.gnss_epochs;
    if (!emit(toIdl(f.fix, c.gnss_receiver_id, seq.gnss_fixes + 1))) return false;
    ++seq.gnss_fixes;
  }
  if (c.publish_gnss && f.has_extra_gnss) {
    // The further receivers' epochs (no fixes of their own), each under its receiver id; none
    // of a receiver that is out.
    const std::size_t receivers = std::min(f.extra_gnss.size(), c.extra_gnss_receiver_ids.size());
    if (seq.extra_gnss.size() < receivers) seq.extra_gnss.resize(receivers, 0);
    for (std::size_t k = 0; k < receivers; ++k) {
      if (f.extra_gnss_silent[k]) continue;
      if (!emit(toIdl(f.extra_gnss[k], c.extra_gnss_receiver_ids[k], seq.extra_gnss[k] + 1)))
        return false;
      ++seq.extra_gnss[k];
    }
  }
  if (c.publish_star_tracker && f.has_star_tracker) {
    if (!emit(toIdl(f.star_tracker, c.star_tracker_id, seq.star_tracker + 1))) return false;
    ++seq.star_tracker;
  }
  return true;
}

class FramePublisher {
 public:
  FramePublisher(bus::Participant& participant, const SimConfig& config);

  /// Writes every sample of the frame (in fast pacing with blocks, every stream's block once
  /// the increment block is full); returns false if the run was stopped meanwhile.
  bool publish(const sim::SensorFrame& frame);
  /// Readers matched on the topic that carries the increments.
  std::size_t imuReaders() const;
  /// True when every enabled topic has at least its configured number of matched readers.
  bool readersMatched() const;
  /// Waits (bounded) until every written sample is acknowledged by the reliable readers.
  void flush();
  /// Writes the blocks still pending, then disposes every stream instance written: readers
  /// see the streams end as announced (the fault manager's watchdog reports no loss). A
  /// crashed simulator cannot do this: its streams are lost.
  void endStreams();

  /// What was written, and writes retried because a reliable reader was behind.
  const WrittenCounts& counts() const { return written_; }
  std::uint64_t writeRetries() const { return write_retries_; }
  /// Increments per ImuIncrementBlock, 0 when each goes out alone.
  std::size_t incrementsPerBlock() const { return increments_per_block_; }

 private:
  template <class Sample>
  bool writeReliably(bus::Writer<Sample>& writer, const Sample& sample);
  /// The writer of a sensor topic (bus/streams.hpp), with the pacing's profile.
  template <class Message>
  bus::Writer<Message> createWriter();
  bool writeIncrement(const navbus::ImuIncrement& increment);
  /// The batcher of an increment's sensor (the scenario's IMU or a further unit's).
  ImuBlockBatcher& batcherOf(std::uint32_t sensor_id);
  bool writeIncrementBlock(ImuBlockBatcher& batcher);
  bool writeRaw(const navbus::ImuRawBlock& raw);
  bool batchRaw(const navbus::ImuRawBlock& raw);
  /// Writes the pending blocks (fast pacing with blocks).
  bool writeBlocks();
  /// An epoch, fix or attitude: written, or (with blocks) added to its sensor's block.
  template <class Block>
  bool writeMeasurement(const typename bus::SensorBlock<Block>::Element& sample);
  template <class Block>
  bool writeMeasurementBlock(MeasurementBlockBatcher<Block>& batcher);
  /// One stream's measurement blocks: its writer and a batcher per sensor id (written in id
  /// order), the measurements written, and their writer one at a time without blocks.
  template <class Block>
  struct BlockStream {
    using BlockType = Block;
    using Element = typename bus::SensorBlock<Block>::Element;
    bus::Writer<Element> single;
    bus::Writer<Block> blocks;
    std::map<std::uint32_t, MeasurementBlockBatcher<Block>> batchers;
    std::uint64_t* written{nullptr};  ///< the count in WrittenCounts
  };
  template <class Block>
  BlockStream<Block>& streamOf();
  template <class Block>
  bool writePendingBlocks(BlockStream<Block>& stream);
  template <class Block>
  void disposeStream(BlockStream<Block>& stream, const std::vector<std::uint32_t>& ids);
  /// The writer that carries a measurement stream now (the block writer with blocks).
  template <class Block>
  std::size_t matchedReaders(const BlockStream<Block>& stream) const;

  bus::Participant& participant_;
  SimConfig config_;
  std::size_t increments_per_block_;
  bus::Writer<navbus::ImuIncrement> imu_;              ///< one increment per sample
  bus::Writer<navbus::ImuIncrementBlock> imu_blocks_;  ///< or blocks of them
  bus::Writer<navbus::ImuRawBlock> raw_;
  WrittenCounts written_;
  BlockStream<navbus::GnssObservationEpochBlock> gnss_;
  BlockStream<navbus::GnssFixBlock> fix_;
  BlockStream<navbus::StarTrackerAttitudeBlock> star_;
  std::optional<ImuBlockBatcher> batcher_;  ///< with blocks
  /// With blocks: the further IMU units' increments, one batcher per unit (in unit order)
  std::vector<ImuBlockBatcher> unit_batchers_;
  FrameSequence sequence_;  ///< the frames' sequence numbers (emitFrame)
  std::uint64_t write_retries_{0};
};

}  // namespace navbus::sensor_sim
