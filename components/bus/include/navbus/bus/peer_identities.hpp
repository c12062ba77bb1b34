// Authenticated identities of the remote participants under DDS Security: the common name of
// each one's certificate (PKI-DH identity token, property dds.cert.sn), by GUID prefix, so that
// a reader can tell which identity wrote a sample (SampleInfo's writer GUID).
#pragma once

#include <map>
#include <mutex>
#include <optional>
#include <string>

#include <fastdds/rtps/common/Guid.h>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>

namespace navbus::bus {

/// The CN of an X.509 subject in OpenSSL's one-line form ("/O=navbus/CN=navbus-filter"), or of
/// an RFC 2253 one ("CN=navbus-filter,O=navbus"); empty if it has none.
std::string commonName(const std::string& subject);

class PeerIdentities : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant* participant,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override;
  /// The certificate CN of the participant `prefix` (nullopt: not discovered or no identity).
  std::optional<std::string> commonName(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) const;

 private:
  mutable std::mutex mutex_;
  std::map<eprosima::fastrtps::rtps::GuidPrefix_t, std::string> names_;
};

}  // namespace navbus::bus
