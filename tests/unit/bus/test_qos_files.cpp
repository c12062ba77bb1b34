// The QoS file rule (navbus/bus/qos_files.hpp): navbus's own profiles are always read, the
// user's --qos file adds and overrides, Fast DDS's default file adds defaults. Fast DDS keeps
// its profiles for the whole process, so each test runs in its own process (tests/CMakeLists
// registers one ctest entry per test with --gtest_filter).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include "navbus/bus/dds_context.hpp"
#include "navbus/bus/qos_files.hpp"
#include "navbus/bus/topics.hpp"

namespace fs = std::filesystem;
namespace fdds = eprosima::fastdds::dds;

namespace {

/// A profile file in a fresh temporary directory with two participant profiles.
std::string writeProfiles(const std::string& file_name, const std::string& first_profile,
                          const std::string& second_profile, bool first_is_default = false) {
  const fs::path dir = fs::temp_directory_path() / ("navbus_qos_files_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / file_name;
  std::ofstream(path) << R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"><profiles>
  <participant profile_name=")"
                      << first_profile << "\""
                      << (first_is_default ? " is_default_profile=\"true\"" : "") << R"(>
    <rtps><builtin><discovery_config><leaseDuration><sec>77</sec></leaseDuration>
    </discovery_config></builtin></rtps>
  </participant>
  <participant profile_name=")"
                      << second_profile << R"(">
    <rtps><builtin><discovery_config><leaseDuration><sec>78</sec></leaseDuration>
    </discovery_config></builtin></rtps>
  </participant>
</profiles></dds>
)";
  return path.string();
}

int leaseSeconds(const std::string& profile) {
  fdds::DomainParticipantQos qos;
  EXPECT_EQ(fdds::DomainParticipantFactory::get_instance()->get_participant_qos_from_profile(
                profile, qos),
            ReturnCode_t::RETCODE_OK)
      << profile;
  return qos.wire_protocol().builtin.discovery_config.leaseDuration.seconds;
}

bool defined(const std::string& profile) {
  fdds::DomainParticipantQos qos;
  return fdds::DomainParticipantFactory::get_instance()->get_participant_qos_from_profile(
             profile, qos) == ReturnCode_t::RETCODE_OK;
}

}  // namespace

TEST(QosFiles, UserFileOverridesAndAdds) {
  const std::string user =
      writeProfiles("mine.xml", navbus::bus::profile::kParticipantLoopback, "my_participant");
  const navbus::bus::QosFiles& files = navbus::bus::loadQosProfiles(user);
  EXPECT_EQ(files.user_file, user);
  ASSERT_EQ(files.overridden.size(), 1u);
  EXPECT_EQ(files.overridden[0], navbus::bus::profile::kParticipantLoopback);
  EXPECT_EQ(leaseSeconds(navbus::bus::profile::kParticipantLoopback), 77);  // the user's
  EXPECT_EQ(leaseSeconds("my_participant"), 78);                            // added
  EXPECT_TRUE(defined("navbus_participant_shm"));                           // navbus's, kept
  EXPECT_NE(files.describe().find(user), std::string::npos);
  EXPECT_NE(files.describe().find(files.navbus_file), std::string::npos);
}

TEST(QosFiles, FastDdsDefaultFileAddsDefaultsBesideNavbus) {
  // The old rule replaced navbus's file by this one: every navbus profile was then missing.
  const std::string defaults =
      writeProfiles("defaults.xml", "my_default_participant", "my_other", true);
  ASSERT_EQ(setenv("FASTRTPS_DEFAULT_PROFILES_FILE", defaults.c_str(), 1), 0);
  const navbus::bus::QosFiles& files = navbus::bus::loadQosProfiles("");
  EXPECT_EQ(files.default_file, defaults);
  EXPECT_TRUE(files.user_file.empty());
  EXPECT_TRUE(defined(navbus::bus::profile::kParticipantLoopback));
  EXPECT_EQ(leaseSeconds("my_other"), 78);
  fdds::DomainParticipantQos qos;
  fdds::DomainParticipantFactory::get_instance()->get_default_participant_qos(qos);
  EXPECT_EQ(qos.wire_protocol().builtin.discovery_config.leaseDuration.seconds, 77);
  EXPECT_NE(files.describe().find("Fast DDS's default file '" + defaults + "'"), std::string::npos);
}

TEST(QosFiles, ErrorsNameTheFile) {
  const auto error = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const navbus::bus::DdsError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error([] {
              navbus::bus::loadQosProfiles("/nonexistent/mine.xml");
            }).find("your QoS file '/nonexistent/mine.xml' cannot be read"),
            std::string::npos);
  const fs::path broken = fs::temp_directory_path() / ("navbus_broken_" + std::to_string(getpid()));
  std::ofstream(broken) << "<dds><profiles><participant";
  EXPECT_NE(error([&] {
              navbus::bus::loadQosProfiles(broken.string());
            }).find("your QoS file '" + broken.string() + "' is not well-formed XML"),
            std::string::npos);
  fs::remove(broken);
  ASSERT_EQ(setenv("FASTRTPS_DEFAULT_PROFILES_FILE", "/nonexistent/defaults.xml", 1), 0);
  EXPECT_NE(error([] { navbus::bus::loadQosProfiles(""); })
                .find("FASTRTPS_DEFAULT_PROFILES_FILE names '/nonexistent/defaults.xml', which "
                      "cannot be read"),
            std::string::npos);
}
