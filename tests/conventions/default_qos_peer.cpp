// A DDS application with Fast DDS's library defaults (participant, topic and reader QoS, no XML
// profile at all), built only on the navbus IDL types: it reads navbus/imu/increment and exits
// 0 once it has received N samples within the time limit, 1 otherwise. With TOPIC and TYPE it
// reads that topic with the type registered under that name (the ROS 2 names:
// rt/navbus/imu/increment, navbus::msg::dds_::ImuIncrement_), as a ROS 2 node's rmw would.
// Usage: navbus_default_qos_peer DOMAIN N TIMEOUT_S [TOPIC TYPE]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include <navbus_idl/ImuPubSubTypes.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>

namespace fdds = eprosima::fastdds::dds;

int main(int argc, char** argv) {
  if (argc != 4 && argc != 6) {
    std::fprintf(stderr, "usage: %s DOMAIN N TIMEOUT_S [TOPIC TYPE]\n", argv[0]);
    return 2;
  }
  const int domain = std::atoi(argv[1]);
  const int wanted = std::atoi(argv[2]);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(std::atof(argv[3]));
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipant* participant = factory->create_participant(
      static_cast<fdds::DomainId_t>(domain), fdds::PARTICIPANT_QOS_DEFAULT);
  if (participant == nullptr) return 3;
  const std::string topic_name = argc == 6 ? argv[4] : "navbus/imu/increment";
  fdds::TypeSupport type(new navbus::ImuIncrementPubSubType());
  const std::string type_name = argc == 6 ? argv[5] : type.get_type_name();
  type.register_type(participant, type_name);
  fdds::Topic* topic = participant->create_topic(topic_name, type_name, fdds::TOPIC_QOS_DEFAULT);
  fdds::DataReader* reader = participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT)
                                 ->create_datareader(topic, fdds::DATAREADER_QOS_DEFAULT);
  int received = 0;
  while (received < wanted && std::chrono::steady_clock::now() < deadline) {
    navbus::ImuIncrement sample;
    fdds::SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) ++received;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::printf("default-QoS application received %d samples of %s (type %s)\n", received,
              topic_name.c_str(), type_name.c_str());
  participant->delete_contained_entities();
  factory->delete_participant(participant);
  return received >= wanted ? 0 : 1;
}
