// DDS Security credentials for a participant. Which plugins run (and so whether a participant
// is secure) is QoS and lives in the participant profiles of qos/navbus_qos.xml; where one
// participant's certificate, key and signed documents are is deployment data and comes from the
// command line or the configuration, as a directory laid out by scripts/make_credentials.sh.
#pragma once

#include <string>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

namespace navbus::bus {

/// The files of an identity directory, in the order the Fast DDS properties are listed.
inline constexpr const char* kIdentityFiles[] = {"identity_ca.pem", "cert.pem",
                                                 "key.pem",         "permissions_ca.pem",
                                                 "governance.p7s",  "permissions.p7s"};

/// True if the participant QoS enables DDS Security (it names an authentication plugin).
bool securityEnabled(const eprosima::fastdds::dds::DomainParticipantQos& qos);

/// Points the security plugins of `qos` (from participant profile `profile`) at the files of
/// `identity_dir`. Throws DdsError naming the profile and the option when the profile is secure
/// and no directory is given, when a directory is given to a profile without security, or
/// when a file of the directory cannot be read.
void applySecurityIdentity(eprosima::fastdds::dds::DomainParticipantQos& qos,
                           const std::string& profile, const std::string& identity_dir);

}  // namespace navbus::bus
