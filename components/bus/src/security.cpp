#include "navbus/bus/security.hpp"

#include <filesystem>
#include <fstream>

#include <fastdds/rtps/attributes/PropertyPolicy.h>

#include "navbus/bus/dds_context.hpp"

namespace navbus::bus {

namespace {

namespace fs = std::filesystem;
using eprosima::fastrtps::rtps::PropertyPolicyHelper;

constexpr const char* kAuthPlugin = "dds.sec.auth.plugin";
constexpr const char* kAuth = "dds.sec.auth.builtin.PKI-DH.";
constexpr const char* kAccess = "dds.sec.access.builtin.Access-Permissions.";

/// The Fast DDS property that names each file of kIdentityFiles.
const std::string kFileProperties[] = {
    std::string(kAuth) + "identity_ca",  std::string(kAuth) + "identity_certificate",
    std::string(kAuth) + "private_key",  std::string(kAccess) + "permissions_ca",
    std::string(kAccess) + "governance", std::string(kAccess) + "permissions"};

}  // namespace

bool securityEnabled(const eprosima::fastdds::dds::DomainParticipantQos& qos) {
  const std::string* plugin = PropertyPolicyHelper::find_property(qos.properties(), kAuthPlugin);
  return plugin != nullptr && !plugin->empty();
}

void applySecurityIdentity(eprosima::fastdds::dds::DomainParticipantQos& qos,
                           const std::string& profile, const std::string& identity_dir) {
  const bool secure = securityEnabled(qos);
  if (!secure) {
    if (!identity_dir.empty()) {
      throw DdsError("a security identity ('" + identity_dir + "') was given but participant " +
                     "profile '" + profile + "' has no DDS Security; choose a *_secure profile");
    }
    return;
  }
  if (identity_dir.empty()) {
    throw DdsError("participant profile '" + profile +
                   "' runs DDS Security: give this participant's credentials directory with "
                   "--identity DIR or the configuration key security_identity (test "
                   "credentials: scripts/make_credentials.sh)");
  }
  const fs::path dir = fs::absolute(identity_dir);
  for (std::size_t i = 0; i < std::size(kIdentityFiles); ++i) {
    const fs::path file = dir / kIdentityFiles[i];
    if (!std::ifstream(file).good()) {
      throw DdsError("security identity '" + identity_dir + "': cannot read " + file.string());
    }
    qos.properties().properties().emplace_back(kFileProperties[i], "file://" + file.string());
  }
}

}  // namespace navbus::bus
