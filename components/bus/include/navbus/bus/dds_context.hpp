// A domain participant created from a named XML profile, with its topics, writers and readers.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "navbus/bus/guarded_type.hpp"
#include "navbus/bus/peer_identities.hpp"

namespace navbus::bus {

/// Thrown when a DDS entity cannot be created; the message names the entity and profile.
class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ParticipantOptions {
  int domain_id{0};
  std::string participant_profile;  ///< a <participant> profile name from the QoS file
  std::string qos_file;             ///< the user's profiles (qos_files.hpp), empty for none
  std::string name;                 ///< participant name shown in discovery and health
  /// DDS Security credentials directory (see security.hpp); required by a secure profile,
  /// refused by any other.
  std::string security_identity;
  /// Discovery server "IP[:PORT]" for a discovery-client profile (discovery_server.hpp); empty:
  /// the profile's.
  std::string discovery_server;
  /// Take the SUPER_CLIENT role under a discovery server (inspection tools: see every endpoint).
  bool discovery_super_client{false};
  /// ROS 2 naming (ros2Names()): topics "rt/<name>", types "<module>::msg::dds_::<Type>_".
  bool ros2_names{false};
  /// Optional listener installed at creation, so that no discovery event is missed.
  eprosima::fastdds::dds::DomainParticipantListener* listener{nullptr};
};

/// A topic's and a type's DDS names under ROS 2's conventions (the rmw_fastrtps mapping):
/// topic "navbus/imu/increment" -> "rt/navbus/imu/increment"; type "navbus::ImuIncrement" ->
/// "navbus::msg::dds_::ImuIncrement_".
std::string ros2TopicName(const std::string& topic);
std::string ros2TypeName(const std::string& type);

class DdsContext {
 public:
  explicit DdsContext(const ParticipantOptions& options);
  ~DdsContext();
  DdsContext(const DdsContext&) = delete;
  DdsContext& operator=(const DdsContext&) = delete;

  /// Registers PubSubType (once) and returns the topic, created on first use.
  template <class PubSubType>
  eprosima::fastdds::dds::Topic* topic(const std::string& name) {
    // With NAVBUS_TYPE_OBJECTS the generated constructors register the type objects
    // (register<File>Types()); one sample constructed before the entities makes sure the type
    // object exists when discovery announces the endpoint.
    [[maybe_unused]] const typename PubSubType::type registers_type_object{};
    eprosima::fastdds::dds::TypeSupport type(new GuardedType<PubSubType>());
    return topicForType(name, type);
  }
  /// The counter of payloads of a registered type that failed to deserialize (GuardedType).
  MalformedCounter* malformedCounter(const std::string& type_name);

  eprosima::fastdds::dds::DataWriter* createWriter(eprosima::fastdds::dds::Topic* topic,
                                                   const std::string& profile);
  eprosima::fastdds::dds::DataReader* createReader(eprosima::fastdds::dds::Topic* topic,
                                                   const std::string& profile);

  /// Waits until the reliable readers matched with this participant's writers acknowledged
  /// every sample written, at most `max_wait`. False if some had not by then.
  bool waitForAcknowledgments(std::chrono::nanoseconds max_wait);

  eprosima::fastdds::dds::DomainParticipant* participant() { return participant_; }
  const std::string& name() const { return name_; }
  /// True if the participant runs DDS Security.
  bool secure() const { return secure_; }
  /// Under DDS Security, the certificate common name of the participant that wrote the sample
  /// (empty if it is not known); nullopt on a plain profile, where nobody is authenticated.
  /// Known only when no listener was passed in the options.
  std::optional<std::string> writerIdentity(const eprosima::fastdds::dds::SampleInfo& info) const;

 private:
  eprosima::fastdds::dds::Topic* topicForType(const std::string& name,
                                              eprosima::fastdds::dds::TypeSupport type);

  std::string name_;
  std::string qos_files_;  ///< the profile files read, for error messages
  bool ros2_names_{false};
  bool secure_{false};
  PeerIdentities peers_;  ///< the participant's listener unless the options bring one
  eprosima::fastdds::dds::DomainParticipant* participant_{nullptr};
  eprosima::fastdds::dds::Publisher* publisher_{nullptr};
  eprosima::fastdds::dds::Subscriber* subscriber_{nullptr};
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
};

/// A duration as Fast DDS takes it (negative: zero).
eprosima::fastrtps::Duration_t toDdsDuration(std::chrono::nanoseconds d);

}  // namespace navbus::bus
