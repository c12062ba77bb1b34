#include "navbus/bus/dds_context.hpp"

#include <algorithm>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include "navbus/bus/discovery_server.hpp"
#include "navbus/bus/qos_files.hpp"
#include "navbus/bus/security.hpp"

namespace navbus::bus {

namespace dds = eprosima::fastdds::dds;

std::string ros2TopicName(const std::string& topic) {
  return "rt/" + topic;
}

std::string ros2TypeName(const std::string& type) {
  const std::size_t last = type.rfind("::");
  const std::string module = last == std::string::npos ? "" : type.substr(0, last + 2);
  const std::string name = last == std::string::npos ? type : type.substr(last + 2);
  return module + "msg::dds_::" + name + "_";
}

DdsContext::DdsContext(const ParticipantOptions& options)
    : name_(options.name), ros2_names_(options.ros2_names) {
  const QosFiles& files = loadQosProfiles(options.qos_file);
  qos_files_ = files.describe();
  auto* factory = dds::DomainParticipantFactory::get_instance();
  dds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile(options.participant_profile, qos) !=
      ReturnCode_t::RETCODE_OK) {
    throw DdsError("participant profile '" + options.participant_profile +
                   "' is not defined in the QoS files read (" + files.describe() + ")");
  }
  applySecurityIdentity(qos, options.participant_profile, options.security_identity);
  applyDiscoveryServer(qos, options.participant_profile, options.discovery_server,
                       options.discovery_super_client);
  secure_ = securityEnabled(qos);
  qos.name(options.name);
  // The listener hears discovery only (mask none): data and statuses go to the waitset.
  participant_ = factory->create_participant(
      static_cast<dds::DomainId_t>(options.domain_id), qos,
      options.listener != nullptr ? options.listener : &peers_, dds::StatusMask::none());
  if (participant_ == nullptr) {
    std::string why = "cannot create participant '" + options.name + "' on domain " +
                      std::to_string(options.domain_id) + " with profile '" +
                      options.participant_profile + "'";
    if (secure_) {
      why += " and security identity '" + options.security_identity +
             "' (its certificate must be signed by its identity_ca.pem, the documents by its "
             "permissions_ca.pem, and permissions.p7s must grant its subject this domain)";
    }
    throw DdsError(why);
  }
  publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr) {
    throw DdsError("cannot create publisher/subscriber of participant '" + options.name + "'");
  }
}

DdsContext::~DdsContext() {
  if (participant_ != nullptr) {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
}

std::optional<std::string> DdsContext::writerIdentity(const dds::SampleInfo& info) const {
  if (!secure_) return std::nullopt;
  return peers_.commonName(info.sample_identity.writer_guid().guidPrefix).value_or("");
}

dds::Topic* DdsContext::topicForType(const std::string& name, dds::TypeSupport type) {
  auto it = topics_.find(name);
  if (it != topics_.end()) {
    return it->second;
  }
  const std::string type_name =
      ros2_names_ ? ros2TypeName(type.get_type_name()) : type.get_type_name();
  if (participant_->find_type(type_name).empty()) {
    // The type object (NAVBUS_TYPE_OBJECTS) is announced for dynamic tools, the XTypes type
    // information is not: Fast DDS 2.9 compares it with a remote endpoint's own and refused
    // Cyclone DDS 0.10's writers with it (interop_cyclone; docs/bus.md, type information).
    type->auto_fill_type_information(false);
    if (type.register_type(participant_, type_name) != ReturnCode_t::RETCODE_OK) {
      throw DdsError("cannot register type '" + type_name + "'");
    }
  }
  const std::string dds_name = ros2_names_ ? ros2TopicName(name) : name;
  dds::Topic* topic = participant_->create_topic(dds_name, type_name, dds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) {
    throw DdsError("cannot create topic '" + dds_name + "' of type '" + type_name + "'");
  }
  topics_.emplace(name, topic);
  return topic;
}

MalformedCounter* DdsContext::malformedCounter(const std::string& type_name) {
  return dynamic_cast<MalformedCounter*>(participant_->find_type(type_name).get());
}

eprosima::fastrtps::Duration_t toDdsDuration(std::chrono::nanoseconds d) {
  const auto ns = std::max<std::int64_t>(0, d.count());
  return eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(ns / 1'000'000'000),
                                        static_cast<std::uint32_t>(ns % 1'000'000'000));
}

bool DdsContext::waitForAcknowledgments(std::chrono::nanoseconds max_wait) {
  return publisher_->wait_for_acknowledgments(toDdsDuration(max_wait)) == ReturnCode_t::RETCODE_OK;
}

dds::DataWriter* DdsContext::createWriter(dds::Topic* topic, const std::string& profile) {
  dds::DataWriter* writer = publisher_->create_datawriter_with_profile(topic, profile);
  if (writer == nullptr) {
    throw DdsError("cannot create writer on '" + topic->get_name() + "' with profile '" + profile +
                   "' (missing profile, inconsistent QoS, or not permitted to this identity; QoS "
                   "files read: " +
                   qos_files_ + ")");
  }
  return writer;
}

dds::DataReader* DdsContext::createReader(dds::Topic* topic, const std::string& profile) {
  dds::DataReader* reader = subscriber_->create_datareader_with_profile(topic, profile);
  if (reader == nullptr) {
    throw DdsError("cannot create reader on '" + topic->get_name() + "' with profile '" + profile +
                   "' (missing profile, inconsistent QoS, or not permitted to this identity; QoS "
                   "files read: " +
                   qos_files_ + ")");
  }
  return reader;
}

}  // namespace navbus::bus
