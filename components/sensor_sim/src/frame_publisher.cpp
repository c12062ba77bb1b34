#include "navbus/sensor_sim/frame_publisher.hpp"

#include <cmath>
#include <type_traits>

#include <spdlog/spdlog.h>

#include "navbus/bus/conversions.hpp"
#include "navbus/bus/streams.hpp"
#include "navbus/core/math/earth.hpp"

namespace navbus::sensor_sim {

using bus::toArray;

navbus::ImuRawBlock toIdl(const sim::RawImuBlock& block, std::uint32_t sensor_id,
                          std::uint64_t seq) {
  navbus::ImuRawBlock msg;
  msg.sensor_id(sensor_id);
  msg.seq(seq);
  msg.first_sample_time_gps_ns(static_cast<std::uint64_t>(block.first_time_ns));
  msg.sample_period_ns(static_cast<std::uint32_t>(std::llround(block.sample_period_s * 1e9)));
  msg.samples().reserve(block.samples.size());
  for (const auto& s : block.samples) {
    navbus::ImuRawSample r;
    r.angular_rate_b_radps(toArray(s.angular_rate_b_radps));
    r.specific_force_b_mps2(toArray(s.specific_force_b_mps2));
    msg.samples().push_back(r);
  }
  return msg;
}

navbus::GnssObservationEpoch toIdl(const sim::GnssEpoch& epoch, std::uint32_t receiver_id,
                                   std::uint64_t seq) {
  navbus::GnssObservationEpoch msg;
  msg.receiver_id(receiver_id);
  msg.seq(seq);
  msg.time_gps_ns(static_cast<std::uint64_t>(epoch.time_ns));
  for (const auto& s : epoch.satellites) {
    navbus::GnssSatelliteMeasurement m;
    m.sv_id(static_cast<std::uint16_t>(s.sv_id));
    m.pseudorange_m(s.pseudorange_m);
    m.pseudorange_rate_mps(s.pseudorange_rate_mps);
    m.sat_pos_ecef_m(toArray(s.sat_pos_ecef_m));
    m.sat_vel_ecef_mps(toArray(s.sat_vel_ecef_mps));
    m.sat_clock_correction_m(s.sat_clock_correction_m);
    m.sat_clock_drift_mps(s.sat_clock_drift_mps);
    m.cn0_dbhz(s.cn0_dbhz);
    m.pseudorange_sigma_m(s.pseudorange_sigma_m);
    m.pseudorange_rate_sigma_mps(s.pseudorange_rate_sigma_mps);
    m.valid(true);
    msg.satellites().push_back(m);
  }
  return msg;
}

navbus::GnssFix toIdl(const sim::GnssFixSample& fix, std::uint32_t receiver_id, std::uint64_t seq) {
  navbus::GnssFix msg;
  msg.receiver_id(receiver_id);
  msg.seq(seq);
  msg.time_gps_ns(static_cast<std::uint64_t>(fix.time_ns));
  msg.latitude_rad(fix.position.latitude_rad);
  msg.longitude_rad(fix.position.longitude_rad);
  msg.height_m(fix.position.height_m);
  msg.pos_ecef_m(toArray(core::earth::geodeticToEcef(fix.position)));
  msg.vel_ned_mps(toArray(fix.vel_ned_mps));
  msg.pos_sigma_ned_m(toArray(fix.pos_sigma_ned_m));
  msg.vel_sigma_ned_mps(toArray(fix.vel_sigma_ned_mps));
  msg.num_satellites_used(static_cast<std::uint16_t>(fix.num_satellites));
  msg.valid(fix.valid);
  return msg;
}

navbus::StarTrackerAttitude toIdl(const sim::StarTrackerSample& st, std::uint32_t tracker_id,
                                  std::uint64_t seq) {
  navbus::StarTrackerAttitude msg;
  msg.tracker_id(tracker_id);
  msg.seq(seq);
  msg.time_gps_ns(static_cast<std::uint64_t>(st.time_ns));
  msg.q_b_to_i() = {st.q_b_to_i.w(), st.q_b_to_i.x(), st.q_b_to_i.y(), st.q_b_to_i.z()};
  msg.sigma_b_rad(toArray(st.sigma_b_rad));
  msg.valid(true);
  return msg;
}

FramePublisher::FramePublisher(bus::Participant& participant, const SimConfig& config)
    : participant_(participant),
      config_(config),
      increments_per_block_(sensor_sim::incrementsPerBlock(config)) {
  if (increments_per_block_ > 0) {
    batcher_.emplace(increments_per_block_);
    unit_batchers_.assign(config.extra_imu_sensor_ids.size(),
                          ImuBlockBatcher(increments_per_block_));
    imu_blocks_ = createWriter<navbus::ImuIncrementBlock>();
  } else {
    imu_ = createWriter<navbus::ImuIncrement>();
  }
  if (config.publish_raw) raw_ = createWriter<navbus::ImuRawBlock>();
  gnss_.written = &written_.gnss_epochs;
  fix_.written = &written_.gnss_fixes;
  star_.written = &written_.star_tracker;
  // With blocks, epochs, fixes and attitudes go in blocks of the frames an increment block covers.
  auto create = [this](auto& stream) {
    using Stream = std::decay_t<decltype(stream)>;
    if (batcher_) {
      stream.blocks = createWriter<typename Stream::BlockType>();
    } else {
      stream.single = createWriter<typename Stream::Element>();
    }
  };
  if (config.publish_gnss) {
    create(gnss_);
    create(fix_);
  }
  if (config.publish_star_tracker) create(star_);
}

template <class Message>
bus::Writer<Message> FramePublisher::createWriter() {
  // Fast pacing writes asynchronously (several samples per datagram); real time synchronously
  // (no thread hop in the latency). qos/navbus_qos.xml says what each measured.
  const bus::SensorTopic& row = bus::SensorMessage<Message>::kTopic;
  return participant_.createWriter<typename bus::SensorMessage<Message>::PubSubType>(
      row.topic, config_.pacing == Pacing::kFast ? row.fast_writer_profile : row.writer_profile);
}

template <class Sample>
bool FramePublisher::writeReliably(bus::Writer<Sample>& writer, const Sample& sample) {
  return writer.writeWaitingForReaders(
      sample, [this] { return participant_.stopping(); }, write_retries_);
}

ImuBlockBatcher& FramePublisher::batcherOf(std::uint32_t sensor_id) {
  const auto& ids = config_.extra_imu_sensor_ids;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] == sensor_id) return unit_batchers_[k];
  }
  return *batcher_;
}

bool FramePublisher::writeIncrement(const navbus::ImuIncrement& increment) {
  if (batcher_) {
    batcherOf(increment.sensor_id()).addIncrement(increment);  // written by writeBlocks
    return true;
  }
  if (!writeReliably(imu_, increment)) return false;
  ++written_.increments;
  ++written_.increment_samples;
  return true;
}

bool FramePublisher::writeRaw(const navbus::ImuRawBlock& raw) {
  if (!writeReliably(raw_, raw)) return false;
  written_.raw_samples += raw.samples().size();
  ++written_.raw_blocks;
  return true;
}

bool FramePublisher::batchRaw(const navbus::ImuRawBlock& raw) {
  if (batcher_->addRaw(raw)) return true;
  // Not a continuation of the pending block (or no room): that one goes first.
  if (batcher_->hasRaw() && !writeRaw(batcher_->takeRaw())) return false;
  if (batcher_->addRaw(raw)) return true;
  return writeRaw(raw);  // longer than any block: as it is
}

bool FramePublisher::writeIncrementBlock(ImuBlockBatcher& batcher) {
  if (!batcher.hasIncrements()) return true;
  const navbus::ImuIncrementBlock block = batcher.takeIncrements();
  if (!writeReliably(imu_blocks_, block)) return false;
  written_.increments += block.increments().size();
  ++written_.increment_samples;
  return true;
}

template <class Block>
FramePublisher::BlockStream<Block>& FramePublisher::streamOf() {
  if constexpr (std::is_same_v<Block, navbus::GnssObservationEpochBlock>) return gnss_;
  if constexpr (std::is_same_v<Block, navbus::GnssFixBlock>) return fix_;
  if constexpr (std::is_same_v<Block, navbus::StarTrackerAttitudeBlock>) return star_;
}

template <class Block>
bool FramePublisher::writeMeasurementBlock(MeasurementBlockBatcher<Block>& batcher) {
  if (batcher.empty()) return true;
  BlockStream<Block>& stream = streamOf<Block>();
  const Block block = batcher.take();
  if (!writeReliably(stream.blocks, block)) return false;
  *stream.written += bus::SensorBlock<Block>::elements(block).size();
  ++written_.measurement_samples;
  return true;
}

template <class Block>
bool FramePublisher::writeMeasurement(const typename bus::SensorBlock<Block>::Element& sample) {
  BlockStream<Block>& stream = streamOf<Block>();
  if (!batcher_) {
    if (!writeReliably(stream.single, sample)) return false;
    ++*stream.written;
    ++written_.measurement_samples;
    return true;
  }
  MeasurementBlockBatcher<Block>& batcher =
      stream.batchers[bus::SensorMessage<typename BlockStream<Block>::Element>::sensorId(sample)];
  if (batcher.add(sample)) return true;
  // The block holds its bound (a stream faster than the blocks): it goes first.
  return writeMeasurementBlock(batcher) && batcher.add(sample);
}

template <class Block>
bool FramePublisher::writePendingBlocks(BlockStream<Block>& stream) {
  for (auto& [id, batcher] : stream.batchers) {
    if (!writeMeasurementBlock(batcher)) return false;
  }
  return true;
}

bool FramePublisher::writeBlocks() {
  // The units' blocks cover the same frames as the scenario IMU's (filled in lockstep), and so
  // do the measurements' blocks: the merge downstream waits for neither.
  if (!writeIncrementBlock(*batcher_)) return false;
  for (ImuBlockBatcher& b : unit_batchers_) {
    if (!writeIncrementBlock(b)) return false;
  }
  if (batcher_->hasRaw() && !writeRaw(batcher_->takeRaw())) return false;
  return writePendingBlocks(gnss_) && writePendingBlocks(fix_) && writePendingBlocks(star_);
}

bool FramePublisher::publish(const sim::SensorFrame& f) {
  const bool written = emitFrame(f, config_, sequence_, [this](const auto& sample) {
    using T = std::decay_t<decltype(sample)>;
    if constexpr (std::is_same_v<T, navbus::ImuIncrement>) return writeIncrement(sample);
    if constexpr (std::is_same_v<T, navbus::ImuRawBlock>)
      return batcher_ ? batchRaw(sample) : writeRaw(sample);
    if constexpr (std::is_same_v<T, navbus::GnssObservationEpoch>)
      return writeMeasurement<navbus::GnssObservationEpochBlock>(sample);
    if constexpr (std::is_same_v<T, navbus::GnssFix>)
      return writeMeasurement<navbus::GnssFixBlock>(sample);
    if constexpr (std::is_same_v<T, navbus::StarTrackerAttitude>)
      return writeMeasurement<navbus::StarTrackerAttitudeBlock>(sample);
  });
  if (!written) return false;
  // A full block of increments goes out with the raw samples and measurements of its frames.
  return !(batcher_ && batcher_->full()) || writeBlocks();
}

template <class Block>
std::size_t FramePublisher::matchedReaders(const BlockStream<Block>& stream) const {
  return batcher_ ? stream.blocks.matchedReaders() : stream.single.matchedReaders();
}

std::size_t FramePublisher::imuReaders() const {
  return batcher_ ? imu_blocks_.matchedReaders() : imu_.matchedReaders();
}

bool FramePublisher::readersMatched() const {
  const auto& m = config_.min_readers;
  auto enough = [](const auto& writer, int wanted) {
    return writer.matchedReaders() >= static_cast<std::size_t>(wanted);
  };
  return imuReaders() >= static_cast<std::size_t>(m.imu) &&
         (!config_.publish_raw || enough(raw_, m.raw_imu)) &&
         (!config_.publish_gnss ||
          (matchedReaders(gnss_) >= static_cast<std::size_t>(m.gnss) &&
           matchedReaders(fix_) >= static_cast<std::size_t>(m.gnss_fix))) &&
         (!config_.publish_star_tracker ||
          matchedReaders(star_) >= static_cast<std::size_t>(m.star_tracker));
}

void FramePublisher::flush() {
  constexpr auto kWait = bus::Participant::kFinishAcknowledgmentWait;
  for (auto* w : {imu_.raw(), imu_blocks_.raw(), raw_.raw(), gnss_.single.raw(), gnss_.blocks.raw(),
                  fix_.single.raw(), fix_.blocks.raw(), star_.single.raw(), star_.blocks.raw()}) {
    if (w != nullptr &&
        w->wait_for_acknowledgments(bus::toDdsDuration(kWait)) != ReturnCode_t::RETCODE_OK) {
      spdlog::warn("{}: not every reliable reader acknowledged the data within {} s",
                   w->get_topic()->get_name(), kWait.count());
    }
  }
}

namespace {
/// Disposes the instance `key` names, if the stream published anything.
template <class Sample>
void disposeIfPublished(bus::Writer<Sample>& writer, std::uint64_t published, const Sample& key) {
  if (published > 0) writer.dispose(key);
}
}  // namespace

template <class Block>
void FramePublisher::disposeStream(BlockStream<Block>& stream,
                                   const std::vector<std::uint32_t>& ids) {
  using Traits = bus::SensorBlock<Block>;
  for (const std::uint32_t id : ids) {
    typename Traits::Element single;
    Block block;
    Traits::setSensorId(block, id);
    Traits::setElementSensorId(single, id);
    disposeIfPublished(stream.single, batcher_ ? 0 : *stream.written, single);
    disposeIfPublished(stream.blocks, batcher_ ? *stream.written : 0, block);
  }
}

void FramePublisher::endStreams() {
  if (batcher_ && !writeBlocks()) return;  // stopped meanwhile
  // Every IMU's instance: the scenario's and each further unit's.
  std::vector<std::uint32_t> imu_ids{config_.imu_sensor_id};
  imu_ids.insert(imu_ids.end(), config_.extra_imu_sensor_ids.begin(),
                 config_.extra_imu_sensor_ids.end());
  for (const std::uint32_t id : imu_ids) {
    navbus::ImuIncrement imu;
    imu.sensor_id(id);
    disposeIfPublished(imu_, batcher_ ? 0 : written_.increment_samples, imu);
    navbus::ImuIncrementBlock imu_block;
    imu_block.sensor_id(id);
    disposeIfPublished(imu_blocks_, batcher_ ? written_.increment_samples : 0, imu_block);
  }
  navbus::ImuRawBlock raw;
  raw.sensor_id(config_.imu_sensor_id);
  disposeIfPublished(raw_, written_.raw_blocks, raw);
  std::vector<std::uint32_t> receiver_ids{config_.gnss_receiver_id};
  receiver_ids.insert(receiver_ids.end(), config_.extra_gnss_receiver_ids.begin(),
                      config_.extra_gnss_receiver_ids.end());
  disposeStream(gnss_, receiver_ids);
  disposeStream(fix_, {config_.gnss_receiver_id});
  disposeStream(star_, {config_.star_tracker_id});
}

}  // namespace navbus::sensor_sim
