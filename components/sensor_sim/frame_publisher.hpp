// Converts simulated sensor frames to IDL samples and writes them, never dropping one:
// a write that times out (a reliable reader is behind) is retried until it succeeds or the
// run is stopped.
#pragma once

#include <cstdint>
#include <functional>

#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "navbus/bus/participant.hpp"
#include "navbus/sim/samples.hpp"
#include "scenario_config.hpp"

namespace navbus::sensor_sim {

navbus::ImuRawBlock toIdl(const sim::RawImuBlock& block, std::uint32_t sensor_id,
                          std::uint64_t seq);
navbus::GnssObservationEpoch toIdl(const sim::GnssEpoch& epoch, std::uint32_t receiver_id,
                                   std::uint64_t seq);
navbus::GnssFix toIdl(const sim::GnssFixSample& fix, std::uint32_t receiver_id, std::uint64_t seq);
navbus::StarTrackerAttitude toIdl(const sim::StarTrackerSample& st, std::uint32_t tracker_id,
                                  std::uint64_t seq);

class FramePublisher {
 public:
  FramePublisher(bus::Participant& participant, const SimConfig& config);

  /// Writes every sample of the frame; returns false if the run was stopped meanwhile.
  bool publish(const sim::SensorFrame& frame);
  /// Readers matched on the IMU increment topic.
  std::size_t imuReaders() const { return imu_.matchedReaders(); }
  /// True when every enabled topic has at least its configured number of matched readers.
  bool readersMatched() const;
  /// Waits (bounded) until every written sample is acknowledged by the reliable readers.
  void flush();

  struct Counts {
    std::uint64_t imu{0}, raw{0}, gnss_epochs{0}, gnss_fixes{0}, star_tracker{0}, write_retries{0};
  };
  const Counts& counts() const { return counts_; }

 private:
  template <class Sample>
  bool writeReliably(bus::Writer<Sample>& writer, const Sample& sample);

  bus::Participant& participant_;
  SimConfig config_;
  bus::Writer<navbus::ImuIncrement> imu_;
  bus::Writer<navbus::ImuRawBlock> raw_;
  bus::Writer<navbus::GnssObservationEpoch> gnss_;
  bus::Writer<navbus::GnssFix> fix_;
  bus::Writer<navbus::StarTrackerAttitude> star_;
  Counts counts_;
};

}  // namespace navbus::sensor_sim
