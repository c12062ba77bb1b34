// A dynamic DDS tool's view of navbus: no navbus type compiled in. It learns the type of
// navbus/imu/increment from discovery (the type object navbus announces when built with
// NAVBUS_TYPE_OBJECTS), builds a DynamicType from it, reads samples through a
// DynamicPubSubType and decodes the fields by name, as Fast DDS Monitor or DDS Record & Replay
// do. Exits 0 once it decoded N samples with seq increasing, 1 otherwise.
// Usage: navbus_dynamic_type_peer DOMAIN N TIMEOUT_S
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>

#include <fastrtps/types/DynamicData.h>
#include <fastrtps/types/DynamicDataFactory.h>
#include <fastrtps/types/DynamicPubSubType.h>
#include <fastrtps/types/DynamicType.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>

namespace fdds = eprosima::fastdds::dds;
namespace types = eprosima::fastrtps::types;

namespace {

constexpr const char* kTopic = "navbus/imu/increment";

/// Keeps the dynamic type of kTopic once discovery delivers it, by either path Fast DDS 2.9
/// offers: the type object itself, or type information to resolve with the type lookup service.
class TypeListener : public fdds::DomainParticipantListener {
 public:
  void on_type_discovery(fdds::DomainParticipant*, const eprosima::fastrtps::rtps::SampleIdentity&,
                         const eprosima::fastrtps::string_255& topic, const types::TypeIdentifier*,
                         const types::TypeObject*, types::DynamicType_ptr dyn_type) override {
    if (topic.to_string() == kTopic && dyn_type) keep(dyn_type);
  }
  void on_type_information_received(fdds::DomainParticipant* participant,
                                    const eprosima::fastrtps::string_255 topic,
                                    const eprosima::fastrtps::string_255 type_name,
                                    const types::TypeInformation& info) override {
    if (topic.to_string() != kTopic) return;
    std::function<void(const std::string&, const types::DynamicType_ptr)> done =
        [this](const std::string&, const types::DynamicType_ptr type) { keep(type); };
    participant->register_remote_type(info, type_name.to_string(), done);
  }
  types::DynamicType_ptr type() {
    std::lock_guard<std::mutex> lock(mutex_);
    return type_;
  }

 private:
  void keep(types::DynamicType_ptr type) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!type_) type_ = type;
  }
  std::mutex mutex_;
  types::DynamicType_ptr type_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s DOMAIN N TIMEOUT_S\n", argv[0]);
    return 2;
  }
  const int wanted = std::atoi(argv[2]);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(std::atof(argv[3]));
  TypeListener listener;
  fdds::DomainParticipantQos qos = fdds::PARTICIPANT_QOS_DEFAULT;
  qos.wire_protocol().builtin.typelookup_config.use_client = true;
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipant* participant = factory->create_participant(
      static_cast<fdds::DomainId_t>(std::atoi(argv[1])), qos, &listener, fdds::StatusMask::all());
  if (participant == nullptr) return 3;

  types::DynamicType_ptr type;
  while (!(type = listener.type()) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!type) {
    std::printf("no type information for %s within the time limit\n", kTopic);
    factory->delete_participant(participant);
    return 1;
  }
  std::printf("type of %s from discovery: %s, %u members\n", kTopic, type->get_name().c_str(),
              type->get_members_count());
  fdds::TypeSupport support(new types::DynamicPubSubType(type));
  support.register_type(participant);
  fdds::Topic* topic =
      participant->create_topic(kTopic, support.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  fdds::DataReader* reader = participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT)
                                 ->create_datareader(topic, fdds::DATAREADER_QOS_DEFAULT);
  int decoded = 0;
  std::uint64_t last_seq = 0;
  bool increasing = true;
  types::DynamicData* data = types::DynamicDataFactory::get_instance()->create_data(type);
  while (decoded < wanted && std::chrono::steady_clock::now() < deadline) {
    fdds::SampleInfo info;
    while (reader->take_next_sample(data, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const std::uint64_t seq = data->get_uint64_value(data->get_member_id_by_name("seq"));
      const std::uint64_t time_ns =
          data->get_uint64_value(data->get_member_id_by_name("time_gps_ns"));
      if (decoded == 0) {
        std::printf("first sample decoded by name: seq %llu, time_gps_ns %llu\n",
                    static_cast<unsigned long long>(seq), static_cast<unsigned long long>(time_ns));
      }
      increasing = increasing && seq > last_seq;
      last_seq = seq;
      ++decoded;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  types::DynamicDataFactory::get_instance()->delete_data(data);
  std::printf("decoded %d samples, seq increasing: %s\n", decoded, increasing ? "yes" : "no");
  participant->delete_contained_entities();
  factory->delete_participant(participant);
  return decoded >= wanted && increasing ? 0 : 1;
}
