// One writer per sensor: the first writer that publishes a sensor id (an instance of a keyed
// stream) owns it. A sample of another writer while the owner is alive is a second writer: two
// sources claim one sensor, and which one is right cannot be told, so the newcomer's samples are
// kept out and counted. When the owner has been silent for the takeover time (a restarted or
// replaced source), the next writer takes the sensor over.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "navbus/bus/health.hpp"

namespace navbus::bus {

/// A DDS writer's GUID (prefix and entity id).
using WriterId = std::array<std::uint8_t, 16>;
WriterId writerId(const eprosima::fastdds::dds::SampleInfo& info);
std::string toString(const WriterId& id);

/// The ownership rule, pure logic (wall time passed in).
class WriterPins {
 public:
  enum class Verdict {
    kOwner,            ///< the owner's sample (or the first writer of the sensor)
    kTakeover,         ///< a new writer after the owner fell silent: it owns the sensor now
    kNewSecondWriter,  ///< another writer while the owner is alive, seen for the first time
    kSecondWriter      ///< the same intruding writer again
  };
  explicit WriterPins(std::int64_t takeover_silence_ns) : takeover_ns_(takeover_silence_ns) {}
  Verdict check(std::uint32_t sensor_id, const WriterId& writer, std::int64_t wall_now_ns);

 private:
  struct Owner {
    WriterId writer;
    std::int64_t last_sample_ns;
  };
  std::int64_t takeover_ns_;
  std::map<std::uint32_t, Owner> owners_;
  std::set<std::pair<std::uint32_t, WriterId>> intruders_;
};

/// WriterPins on one reader: counts a second writer's samples as rejected (second_writer) in
/// the stream's health and logs each new one.
class WriterGate {
 public:
  /// The default takeover time is the sensor profiles' liveliness lease (1 s): a writer that
  /// has not written for that long is one DDS would declare dead.
  static constexpr std::int64_t kDefaultTakeoverNs = 1'000'000'000;
  WriterGate(std::string topic, StreamCounters& counters,
             std::int64_t takeover_silence_ns = kDefaultTakeoverNs)
      : topic_(std::move(topic)), counters_(counters), pins_(takeover_silence_ns) {}
  /// Judges the sample's writer (steady clock); false if the sample is to be kept out.
  WriterPins::Verdict check(std::uint32_t sensor_id,
                            const eprosima::fastdds::dds::SampleInfo& info);
  bool admit(std::uint32_t sensor_id, const eprosima::fastdds::dds::SampleInfo& info) {
    const auto v = check(sensor_id, info);
    return v == WriterPins::Verdict::kOwner || v == WriterPins::Verdict::kTakeover;
  }

 private:
  std::string topic_;
  StreamCounters& counters_;
  WriterPins pins_;
};

}  // namespace navbus::bus
