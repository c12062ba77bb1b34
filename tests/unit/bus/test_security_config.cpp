// DDS Security set-up without a bus: certificate names, the identity options against the
// participant profile (a clear error naming profile, option or file, never a silent plain
// participant), issuer identities in the filter configuration.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>

#include "navbus/bus/config.hpp"
#include "navbus/bus/dds_context.hpp"
#include "navbus/bus/peer_identities.hpp"
#include "navbus/bus/qos_files.hpp"
#include "navbus/bus/security.hpp"
#include "navbus/nav_filter/filter_config.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
namespace fdds = eprosima::fastdds::dds;
using navbus::bus::DdsError;

namespace {

fdds::DomainParticipantQos profileQos(const std::string& profile) {
  navbus::bus::loadQosProfiles("");
  fdds::DomainParticipantQos qos;
  EXPECT_EQ(fdds::DomainParticipantFactory::get_instance()->get_participant_qos_from_profile(
                profile, qos),
            ReturnCode_t::RETCODE_OK);
  return qos;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const DdsError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SecurityConfig, CommonNameOfBothSubjectForms) {
  EXPECT_EQ(navbus::bus::commonName("/O=navbus/CN=navbus-filter"), "navbus-filter");
  EXPECT_EQ(navbus::bus::commonName("CN=navbus-operator,O=navbus"), "navbus-operator");
  EXPECT_EQ(navbus::bus::commonName("O=navbus, CN=x y"), "x y");
  EXPECT_EQ(navbus::bus::commonName("/O=navbus"), "");
  EXPECT_EQ(navbus::bus::commonName(""), "");
}

TEST(SecurityConfig, ProfilesAndIdentitiesMustAgree) {
  const auto secure = profileQos("navbus_participant_udp_loopback_secure");
  const auto plain = profileQos("navbus_participant_udp_loopback");
  EXPECT_TRUE(navbus::bus::securityEnabled(secure));
  EXPECT_FALSE(navbus::bus::securityEnabled(plain));

  auto q = secure;
  const std::string no_identity = errorOf(
      [&] { navbus::bus::applySecurityIdentity(q, "navbus_participant_udp_loopback_secure", ""); });
  EXPECT_NE(no_identity.find("navbus_participant_udp_loopback_secure"), std::string::npos);
  EXPECT_NE(no_identity.find("--identity"), std::string::npos);

  q = plain;
  const std::string on_plain = errorOf([&] {
    navbus::bus::applySecurityIdentity(q, "navbus_participant_udp_loopback", "/some/dir");
  });
  EXPECT_NE(on_plain.find("has no DDS Security"), std::string::npos) << on_plain;

  const fs::path dir = fs::temp_directory_path() / "navbus-identity-partial";
  fs::create_directories(dir);
  for (const char* f : {"identity_ca.pem", "cert.pem"}) std::ofstream(dir / f) << "x";
  q = secure;
  const std::string missing = errorOf([&] {
    navbus::bus::applySecurityIdentity(q, "navbus_participant_udp_loopback_secure", dir.string());
  });
  EXPECT_NE(missing.find((dir / "key.pem").string()), std::string::npos) << missing;
  fs::remove_all(dir);

  // A complete directory: the six file properties, as file:// URIs of absolute paths.
  q = secure;
  const std::size_t before = q.properties().properties().size();
  navbus::bus::applySecurityIdentity(q, "navbus_participant_udp_loopback_secure",
                                     std::string(navbus::test_paths::credentialsDir()) + "/filter");
  ASSERT_EQ(q.properties().properties().size(), before + 6);
  EXPECT_EQ(q.properties().properties().back().value().rfind("file:///", 0), 0u);
}

TEST(SecurityConfig, IssuerIdentitiesDefaultAndMustNameConfiguredIssuers) {
  YAML::Node n = YAML::Load(
      "initial_state: {latitude_deg: 0, longitude_deg: 0, height_m: 0}\n"
      "inputs: {imu: {id: 1, period_s: 0.01}}\n"
      "issuer_identities: {operator: console-7}\n");
  const auto c = navbus::nav_filter::parseFilterConfig(n);
  EXPECT_EQ(c.issuer_identities.at("operator"), "console-7");
  EXPECT_EQ(c.issuer_identities.at("fault-manager"), "navbus-fault-manager");
  n["issuer_identities"]["intruder"] = "x";
  try {
    navbus::nav_filter::parseFilterConfig(n);
    FAIL() << "an identity for an issuer not in command_issuers was accepted";
  } catch (const navbus::bus::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("'intruder' is not one of command_issuers"),
              std::string::npos)
        << e.what();
  }
}
