// Where a participant finds its discovery server, and in which role. The discovery-client
// profiles of qos/navbus_qos.xml name a server on 127.0.0.1:11811 (`fastdds discovery -i 0`);
// the server's address is deployment data and can be given on the command line
// (--discovery-server IP[:PORT]) or in the configuration (discovery_server). A client only
// learns the endpoints that match its own; the inspection tools (topics, echo, record) take the
// SUPER_CLIENT role, which learns every endpoint the server knows.
#pragma once

#include <string>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

namespace navbus::bus {

/// Points a client profile's server list at `address` ("IP" or "IP:PORT", server id 0; empty:
/// the profile's list), and turns a CLIENT into a SUPER_CLIENT when `super_client`. Throws
/// DdsError naming the profile when an address is given to a profile that is no client, and
/// ConfigError naming the value when the address is not IPv4[:port].
void applyDiscoveryServer(eprosima::fastdds::dds::DomainParticipantQos& qos,
                          const std::string& profile, const std::string& address,
                          bool super_client);

}  // namespace navbus::bus
