// Which Fast DDS XML profile files a navbus process reads, in which order, and where navbus's
// own file is. The rule (docs/bus.md, "QoS profiles"): Fast DDS keeps the first definition of a
// profile name it reads, so the files are read in the order of precedence:
//   1. the user's file (--qos or the configuration's qos_file): adds profiles, and overrides
//      navbus's profiles of the same name (navbus's definitions of those are left out);
//   2. navbus's own file, always: share/navbus/qos/navbus_qos.xml beside the installed
//      executable, else the source tree the build came from;
//   3. Fast DDS's default file, as Fast DDS documents it: FASTRTPS_DEFAULT_PROFILES_FILE, or
//      DEFAULT_FASTRTPS_PROFILES.xml in the working directory. It gives the user's defaults
//      (is_default_profile) and extra profiles; a profile named like one of navbus's is
//      ignored there (Fast DDS logs it), use --qos to override one.
#pragma once

#include <string>
#include <vector>

namespace navbus::bus {

/// The files read by loadQosProfiles, for messages.
struct QosFiles {
  std::string user_file;     ///< --qos / qos_file, empty if none
  std::string navbus_file;   ///< navbus's own profiles
  std::string default_file;  ///< Fast DDS's default file, empty if none exists
  /// Profile names (and transport ids) of navbus's file that the user's file overrides.
  std::vector<std::string> overridden;
  /// "user file A, navbus file B, Fast DDS default file C" for error messages.
  std::string describe() const;
};

/// navbus's own profile file: `<prefix>/share/navbus/qos/navbus_qos.xml` if the running
/// executable lives in `<prefix>/bin` and that file exists, else the source tree's file.
std::string navbusQosFile();

/// Reads the profile files once per process in the order above (a later call with another
/// user file adds that file). Throws DdsError naming the file that cannot be read or parsed.
const QosFiles& loadQosProfiles(const std::string& user_file);

}  // namespace navbus::bus
