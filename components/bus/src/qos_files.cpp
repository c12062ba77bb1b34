#include "navbus/bus/qos_files.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>

#include <spdlog/spdlog.h>
#include <tinyxml2.h>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>

#include "navbus/bus/dds_context.hpp"

#ifndef NAVBUS_QOS_FILE_SOURCE_TREE
#error "NAVBUS_QOS_FILE_SOURCE_TREE must be defined by the build"
#endif

namespace navbus::bus {

namespace fs = std::filesystem;
namespace dds = eprosima::fastdds::dds;

namespace {

constexpr const char* kInstalledQosFile = "share/navbus/qos/navbus_qos.xml";
constexpr const char* kFastDdsDefaultFileEnv = "FASTRTPS_DEFAULT_PROFILES_FILE";
constexpr const char* kFastDdsDefaultFileName = "DEFAULT_FASTRTPS_PROFILES.xml";

/// The <profiles> element of a Fast DDS XML document (root <dds><profiles> or <profiles>).
tinyxml2::XMLElement* profilesElement(tinyxml2::XMLDocument& doc) {
  tinyxml2::XMLElement* root = doc.RootElement();
  if (root == nullptr) return nullptr;
  if (std::string(root->Name()) == "profiles") return root;
  return root->FirstChildElement("profiles");
}

void parse(tinyxml2::XMLDocument& doc, const std::string& file, const std::string& role) {
  if (!std::ifstream(file).good()) {
    throw DdsError(role + " QoS file '" + file + "' cannot be read");
  }
  if (doc.LoadFile(file.c_str()) != tinyxml2::XML_SUCCESS) {
    throw DdsError(role + " QoS file '" + file + "' is not well-formed XML: " + doc.ErrorStr());
  }
}

/// The name an element of <profiles> defines: profile_name, or a transport descriptor's id.
std::string definedName(const tinyxml2::XMLElement& element) {
  if (const char* name = element.Attribute("profile_name")) return name;
  if (const tinyxml2::XMLElement* id = element.FirstChildElement("transport_id")) {
    return id->GetText() != nullptr ? id->GetText() : "";
  }
  return "";
}

/// Every profile name and transport id a document defines.
std::set<std::string> definedNames(tinyxml2::XMLDocument& doc) {
  std::set<std::string> names;
  tinyxml2::XMLElement* profiles = profilesElement(doc);
  for (auto* e = profiles ? profiles->FirstChildElement() : nullptr; e != nullptr;
       e = e->NextSiblingElement()) {
    if (std::string(e->Name()) == "transport_descriptors") {
      for (auto* t = e->FirstChildElement(); t != nullptr; t = t->NextSiblingElement()) {
        names.insert(definedName(*t));
      }
    } else {
      names.insert(definedName(*e));
    }
  }
  names.erase("");
  return names;
}

/// Removes from `doc` the definitions named in `names`; returns the names removed.
std::vector<std::string> removeDefinitions(tinyxml2::XMLDocument& doc,
                                           const std::set<std::string>& names) {
  std::vector<std::string> removed;
  const auto prune = [&](tinyxml2::XMLElement* parent) {
    for (auto* e = parent->FirstChildElement(); e != nullptr;) {
      auto* next = e->NextSiblingElement();
      const std::string name = definedName(*e);
      if (names.count(name) != 0) {
        removed.push_back(name);
        parent->DeleteChild(e);
      } else if (std::string(e->Name()) == "transport_descriptors") {
        for (auto* t = e->FirstChildElement(); t != nullptr;) {
          auto* next_t = t->NextSiblingElement();
          if (names.count(definedName(*t)) != 0) {
            removed.push_back(definedName(*t));
            e->DeleteChild(t);
          }
          t = next_t;
        }
      }
      e = next;
    }
  };
  if (tinyxml2::XMLElement* profiles = profilesElement(doc)) prune(profiles);
  return removed;
}

void loadFile(const std::string& file, const std::string& role) {
  if (dds::DomainParticipantFactory::get_instance()->load_XML_profiles_file(file) !=
      ReturnCode_t::RETCODE_OK) {
    throw DdsError(role + " QoS file '" + file +
                   "' could not be parsed as Fast DDS XML profiles (Fast DDS logs the element)");
  }
}

/// navbus's file without the definitions the user's file overrides; `navbus_names` receives
/// every name the file defines.
std::vector<std::string> loadNavbusFile(const std::string& file,
                                        const std::set<std::string>& overridden_names,
                                        std::set<std::string>& navbus_names) {
  tinyxml2::XMLDocument doc;
  parse(doc, file, "navbus");
  navbus_names = definedNames(doc);
  std::vector<std::string> removed = removeDefinitions(doc, overridden_names);
  if (removed.empty()) {
    loadFile(file, "navbus");
    return removed;
  }
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  if (dds::DomainParticipantFactory::get_instance()->load_XML_profiles_string(
          printer.CStr(), static_cast<size_t>(printer.CStrSize() - 1)) !=
      ReturnCode_t::RETCODE_OK) {
    throw DdsError("navbus QoS file '" + file +
                   "' (less the profiles your file overrides) could not be parsed");
  }
  return removed;
}

/// Fast DDS's default file, as Fast DDS finds it; empty if there is none.
std::string fastDdsDefaultFile() {
  const char* env = std::getenv(kFastDdsDefaultFileEnv);
  if (env != nullptr && *env != '\0') {
    if (!std::ifstream(env).good()) {
      throw DdsError(std::string(kFastDdsDefaultFileEnv) + " names '" + env +
                     "', which cannot be read");
    }
    return env;
  }
  return fs::exists(kFastDdsDefaultFileName) ? kFastDdsDefaultFileName : "";
}

/// Fast DDS keeps navbus's definition of a name the default file defines too (it logs an error
/// per name); say why, and how to override one.
void warnAboutNavbusNames(const std::string& default_file,
                          const std::set<std::string>& navbus_names) {
  tinyxml2::XMLDocument doc;
  parse(doc, default_file, "Fast DDS's default");
  std::string shared;
  for (const std::string& name : definedNames(doc)) {
    if (navbus_names.count(name) != 0) shared += (shared.empty() ? "" : ", ") + name;
  }
  if (!shared.empty()) {
    spdlog::warn(
        "Fast DDS's default file '{}' defines profiles navbus defines ({}): navbus's "
        "are used; pass the file with --qos to override them",
        default_file, shared);
  }
}

}  // namespace

std::string QosFiles::describe() const {
  std::string text;
  if (!user_file.empty()) text += "your file '" + user_file + "', ";
  text += "navbus's file '" + navbus_file + "'";
  if (!default_file.empty()) text += ", Fast DDS's default file '" + default_file + "'";
  return text;
}

std::string navbusQosFile() {
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (!error && exe.parent_path().filename() == "bin") {
    const fs::path installed = exe.parent_path().parent_path() / kInstalledQosFile;
    if (fs::exists(installed, error)) return installed.string();
  }
  return NAVBUS_QOS_FILE_SOURCE_TREE;
}

const QosFiles& loadQosProfiles(const std::string& user_file) {
  static std::mutex mutex;
  static QosFiles files;
  static std::set<std::string> users_loaded;
  static std::set<std::string> navbus_names;
  std::lock_guard<std::mutex> lock(mutex);
  if (!user_file.empty() && users_loaded.count(user_file) == 0) {
    tinyxml2::XMLDocument doc;
    parse(doc, user_file, "your");
    loadFile(user_file, "your");
    users_loaded.insert(user_file);
    if (files.navbus_file.empty()) {
      files.user_file = user_file;
      const std::set<std::string> names = definedNames(doc);
      files.navbus_file = navbusQosFile();
      files.overridden = loadNavbusFile(files.navbus_file, names, navbus_names);
    }
  }
  if (files.navbus_file.empty()) {
    files.navbus_file = navbusQosFile();
    loadNavbusFile(files.navbus_file, {}, navbus_names);
  }
  if (files.default_file.empty()) {
    files.default_file = fastDdsDefaultFile();
    if (!files.default_file.empty()) {
      warnAboutNavbusNames(files.default_file, navbus_names);
      loadFile(files.default_file, "Fast DDS's default");
      // Fast DDS's own loading of its default file (the file is read once: it finds it loaded)
      // is what makes the file's is_default_profile participant its default QoS.
      dds::DomainParticipantFactory::get_instance()->load_profiles();
    }
  }
  return files;
}

}  // namespace navbus::bus
