#include "navbus/bus/peer_identities.hpp"

#include <fastdds/rtps/participant/ParticipantDiscoveryInfo.h>

namespace navbus::bus {

std::string commonName(const std::string& subject) {
  const bool one_line = !subject.empty() && subject.front() == '/';
  const char separator = one_line ? '/' : ',';
  std::size_t start = 0;
  while (start <= subject.size()) {
    std::size_t end = subject.find(separator, start);
    if (end == std::string::npos) end = subject.size();
    std::string part = subject.substr(start, end - start);
    const std::size_t first = part.find_first_not_of(' ');
    if (first != std::string::npos && part.compare(first, 3, "CN=") == 0)
      return part.substr(first + 3);
    start = end + 1;
  }
  return {};
}

void PeerIdentities::on_participant_discovery(
    eprosima::fastdds::dds::DomainParticipant*,
    eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) {
  using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERY_STATUS;
  const auto prefix = info.info.m_guid.guidPrefix;
  std::lock_guard<std::mutex> lock(mutex_);
  if (info.status == Status::REMOVED_PARTICIPANT || info.status == Status::DROPPED_PARTICIPANT) {
    names_.erase(prefix);
    return;
  }
  for (const auto& property : info.info.identity_token_.properties()) {
    if (property.name() == "dds.cert.sn") {
      names_[prefix] = bus::commonName(property.value());
      return;
    }
  }
}

std::optional<std::string> PeerIdentities::commonName(
    const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = names_.find(prefix);
  if (it == names_.end()) return std::nullopt;
  return it->second;
}

}  // namespace navbus::bus
