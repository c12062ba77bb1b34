#include "navbus/bus/writer_gate.hpp"

#include <chrono>
#include <cstring>

#include <spdlog/spdlog.h>

namespace navbus::bus {

WriterId writerId(const eprosima::fastdds::dds::SampleInfo& info) {
  const auto& guid = info.sample_identity.writer_guid();
  WriterId id{};
  std::memcpy(id.data(), guid.guidPrefix.value, 12);
  std::memcpy(id.data() + 12, guid.entityId.value, 4);
  return id;
}

std::string toString(const WriterId& id) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string s;
  for (std::size_t i = 0; i < id.size(); ++i) {
    if (i == 12) s += '|';
    s += kHex[id[i] >> 4];
    s += kHex[id[i] & 0xf];
  }
  return s;
}

WriterPins::Verdict WriterPins::check(std::uint32_t sensor_id, const WriterId& writer,
                                      std::int64_t wall_now_ns) {
  auto it = owners_.find(sensor_id);
  if (it == owners_.end()) {
    owners_.emplace(sensor_id, Owner{writer, wall_now_ns});
    return Verdict::kOwner;
  }
  Owner& owner = it->second;
  if (owner.writer == writer) {
    owner.last_sample_ns = wall_now_ns;
    return Verdict::kOwner;
  }
  if (wall_now_ns - owner.last_sample_ns >= takeover_ns_) {
    owner = Owner{writer, wall_now_ns};
    intruders_.erase({sensor_id, writer});
    return Verdict::kTakeover;
  }
  return intruders_.insert({sensor_id, writer}).second ? Verdict::kNewSecondWriter
                                                       : Verdict::kSecondWriter;
}

WriterPins::Verdict WriterGate::check(std::uint32_t sensor_id,
                                      const eprosima::fastdds::dds::SampleInfo& info) {
  const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                               std::chrono::steady_clock::now().time_since_epoch())
                               .count();
  const WriterId writer = writerId(info);
  const auto verdict = pins_.check(sensor_id, writer, now);
  switch (verdict) {
    case WriterPins::Verdict::kOwner:
      break;
    case WriterPins::Verdict::kTakeover:
      spdlog::info("{}: sensor {} taken over by writer {} (the previous one fell silent)", topic_,
                   sensor_id, toString(writer));
      break;
    case WriterPins::Verdict::kNewSecondWriter:
      spdlog::warn(
          "{}: a second writer {} publishes sensor {} while its owner is alive: its "
          "samples are kept out (second_writer)",
          topic_, toString(writer), sensor_id);
      [[fallthrough]];
    case WriterPins::Verdict::kSecondWriter:
      ++counters_.rejected[navbus::REJECT_SECOND_WRITER];
      break;
  }
  return verdict;
}

}  // namespace navbus::bus
