#include "navbus/bus/discovery_server.hpp"

#include <charconv>

#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastrtps/utils/IPLocator.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/dds_context.hpp"

namespace navbus::bus {

namespace {

namespace rtps = eprosima::fastrtps::rtps;
using eprosima::fastdds::rtps::DEFAULT_ROS2_SERVER_PORT;

rtps::Locator_t serverLocator(const std::string& address) {
  const std::size_t colon = address.find(':');
  const std::string ip = address.substr(0, colon);
  unsigned port = DEFAULT_ROS2_SERVER_PORT;
  if (colon != std::string::npos) {
    const char* end = address.data() + address.size();
    const auto [ptr, ec] = std::from_chars(address.data() + colon + 1, end, port);
    if (ec != std::errc() || ptr != end || port == 0 || port > 65535) port = 0;
  }
  if (!rtps::IPLocator::isIPv4(ip) || port == 0) {
    throw ConfigError("discovery server '" + address +
                      "' is not IPv4[:port] (e.g. 10.0.0.2:11811)");
  }
  rtps::Locator_t locator;
  locator.kind = LOCATOR_KIND_UDPv4;
  rtps::IPLocator::setIPv4(locator, ip);
  locator.port = port;
  return locator;
}

}  // namespace

void applyDiscoveryServer(eprosima::fastdds::dds::DomainParticipantQos& qos,
                          const std::string& profile, const std::string& address,
                          bool super_client) {
  auto& discovery = qos.wire_protocol().builtin.discovery_config;
  const bool client = discovery.discoveryProtocol == rtps::DiscoveryProtocol_t::CLIENT ||
                      discovery.discoveryProtocol == rtps::DiscoveryProtocol_t::SUPER_CLIENT;
  if (!client) {
    if (!address.empty()) {
      throw DdsError("a discovery server address ('" + address +
                     "') needs a discovery-client "
                     "profile (e.g. navbus_participant_discovery_client); '" +
                     profile + "' does not use a discovery server");
    }
    return;
  }
  if (!address.empty()) {
    rtps::RemoteServerAttributes server;
    rtps::get_server_client_default_guidPrefix(0, server.guidPrefix);
    server.metatrafficUnicastLocatorList.push_back(serverLocator(address));
    discovery.m_DiscoveryServers.clear();
    discovery.m_DiscoveryServers.push_back(server);
  }
  if (super_client) discovery.discoveryProtocol = rtps::DiscoveryProtocol_t::SUPER_CLIENT;
}

}  // namespace navbus::bus
