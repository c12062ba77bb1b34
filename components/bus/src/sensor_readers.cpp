#include "navbus/bus/sensor_readers.hpp"

namespace navbus::bus {

bool SensorReaders::admit(StreamKind kind, WriterGate& writers, std::uint32_t sensor_id,
                          std::uint64_t time_gps_ns,
                          const eprosima::fastdds::dds::SampleInfo& info) {
  switch (writers.check(sensor_id, info)) {
    case WriterPins::Verdict::kNewSecondWriter:
      if (events_.second_writer) events_.second_writer(kind, sensor_id, time_gps_ns);
      return false;
    case WriterPins::Verdict::kSecondWriter:
      return false;
    case WriterPins::Verdict::kOwner:
    case WriterPins::Verdict::kTakeover:
      break;
  }
  instances_[{kind, info.instance_handle}] = Instance{sensor_id, time_gps_ns};
  return true;
}

const SensorReaders::Instance* SensorReaders::instanceOf(
    StreamKind kind, const eprosima::fastrtps::rtps::InstanceHandle_t& handle) const {
  const auto it = instances_.find({kind, handle});
  return it == instances_.end() ? nullptr : &it->second;
}

ReaderCallbacks SensorReaders::callbacks(StreamKind kind) {
  ReaderCallbacks callbacks;
  if (events_.ended) {
    callbacks.on_disposed = [this, kind](const eprosima::fastrtps::rtps::InstanceHandle_t& h) {
      if (const Instance* i = instanceOf(kind, h))
        events_.ended(kind, i->sensor_id, i->last_time_gps_ns);
    };
  }
  if (events_.deadline_missed) {
    callbacks.on_deadline =
        [this, kind](const eprosima::fastdds::dds::RequestedDeadlineMissedStatus& st) {
          if (const Instance* i = instanceOf(kind, st.last_instance_handle))
            events_.deadline_missed(kind, i->sensor_id);
        };
  }
  if (events_.writers_gone || events_.writers_alive) {
    callbacks.on_liveliness = [this,
                               kind](const eprosima::fastdds::dds::LivelinessChangedStatus& st) {
      if (events_.writers_gone && st.alive_count == 0 && st.alive_count_change < 0)
        events_.writers_gone(kind);
      if (events_.writers_alive) events_.writers_alive(kind, st.alive_count > 0);
    };
  }
  return callbacks;
}

}  // namespace navbus::bus
