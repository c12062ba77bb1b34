#include "navbus/bus/app.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>

#include "navbus/bus/config.hpp"
#include "navbus/bus/realtime.hpp"
#include "navbus/bus/topics.hpp"

namespace navbus::bus {

void addCommonOptions(CLI::App& app, CommonOptions& o, bool config_required) {
  auto* config = app.add_option("-c,--config", o.config_file, "YAML configuration file");
  if (config_required) {
    config->required();
  }
  app.add_option("-d,--domain", o.domain_id, "DDS domain id (overrides the configuration)")
      ->check(CLI::Range(0, 232));
  app.add_option(
      "--qos", o.qos_file,
      "your Fast DDS XML profiles: added to navbus's, overriding its profiles of the same "
      "name (FASTRTPS_DEFAULT_PROFILES_FILE is read after both, as Fast DDS's defaults)");
  app.add_option(
      "--profile", o.participant_profile,
      "participant profile name in the QoS file (default: navbus_participant_udp_loopback)");
  app.add_option("--identity", o.security_identity,
                 "DDS Security credentials directory, for a *_secure profile "
                 "(scripts/make_credentials.sh makes test ones)");
  app.add_option("--discovery-server", o.discovery_server,
                 "IP[:PORT] of the discovery server (server id 0, port 11811 by default) for a "
                 "discovery-client --profile");
  app.add_flag("--ros2", o.ros2_names,
               "ROS 2 naming: topics rt/<name>, types navbus::msg::dds_::<Type>_ (docs/bus.md)");
  app.add_option("--log-level", o.log_level, "trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
}

Participant::Options participantOptions(const CommonOptions& o, const YAML::Node& cfg,
                                        const std::string& name) {
  Participant::Options p;
  p.dds.name = name;
  p.dds.domain_id = o.domain_id >= 0 ? o.domain_id : get<int>(cfg, "", "domain_id", 0);
  checkRange(p.dds.domain_id, 0, 232, "domain_id");
  p.dds.qos_file = !o.qos_file.empty() ? o.qos_file : get<std::string>(cfg, "", "qos_file", "");
  p.dds.participant_profile =
      !o.participant_profile.empty()
          ? o.participant_profile
          : get<std::string>(cfg, "", "participant_profile", profile::kParticipantLoopback);
  p.dds.security_identity = !o.security_identity.empty()
                                ? o.security_identity
                                : get<std::string>(cfg, "", "security_identity", "");
  p.dds.discovery_server = !o.discovery_server.empty()
                               ? o.discovery_server
                               : get<std::string>(cfg, "", "discovery_server", "");
  p.dds.ros2_names = o.ros2_names || get<bool>(cfg, "", "ros2_names", false);
  const double health_s =
      checkRange(get<double>(cfg, "", "health_period_s", 1.0), 0.05, 60.0, "health_period_s");
  p.health_period = std::chrono::milliseconds(static_cast<long>(health_s * 1000.0));
  p.realtime = readRealtime(cfg);
  return p;
}

int runMain(CLI::App& app, int argc, char** argv, CommonOptions& options,
            const std::function<int(const YAML::Node& config)>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitConfigError;
  }
  auto logger = spdlog::stderr_color_mt(app.get_name());
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::from_str(options.log_level));
  spdlog::set_pattern("[%H:%M:%S.%e] [%n] [%l] %v");
  try {
    const YAML::Node config = options.config_file.empty() ? YAML::Node(YAML::NodeType::Map)
                                                          : loadYamlFile(options.config_file);
    try {
      return body(config);
    } catch (const ConfigError& e) {
      if (options.config_file.empty()) throw;
      rethrowNamingFile(options.config_file, e);
    }
  } catch (const ConfigError& e) {
    spdlog::error("{}", e.what());
    return kExitConfigError;
  } catch (const DdsError& e) {
    spdlog::error("{}", e.what());
    return kExitDdsError;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntimeError;
  }
}

}  // namespace navbus::bus
