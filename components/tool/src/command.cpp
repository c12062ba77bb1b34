#include "navbus/tool/command.hpp"

#include <chrono>

#include <navbus_idl/FaultPubSubTypes.h>
#include <spdlog/spdlog.h>

#include "navbus/bus/app.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/records/csv_messages.hpp"
#include "navbus/records/formatters.hpp"
#include "navbus/tool/spin.hpp"

namespace navbus::tool {

namespace {

/// The enumerator named `name`, with or without the IDL prefix enumName() leaves out.
template <class E>
E enumOption(const std::string& option, const std::string& name, const std::string& idl_prefix) {
  const std::string bare = name.rfind(idl_prefix, 0) == 0 ? name.substr(idl_prefix.size()) : name;
  return records::enumFromName<E>(bare, "--" + option);
}

}  // namespace

navbus::FilterCommand buildCommand(const CommandOptions& o, std::uint64_t run_id_ns) {
  navbus::FilterCommand c;
  c.kind(enumOption<navbus::CommandKind>("kind", o.kind, "CMD_"));
  c.command_id(o.command_id != 0 ? o.command_id : run_id_ns);
  c.vehicle_id(o.vehicle_id);
  c.decision_id(o.decision_id);
  c.time_gps_ns(o.time_gps_ns);
  c.onset_time_gps_ns(o.onset_time_gps_ns);
  c.sv_id(o.sv_id);
  c.scope(enumOption<navbus::SatelliteScope>("scope", o.scope, "SCOPE_"));
  if (!o.sensor.empty()) c.sensor(enumOption<navbus::FaultSource>("sensor", o.sensor, "SOURCE_"));
  c.sensor_id(o.sensor_id);
  if (o.axis > 2) throw bus::ConfigError("--axis " + std::to_string(o.axis) + " must be 0, 1 or 2");
  c.axis(o.axis);
  c.bias(o.bias);
  if (!(o.bias_sigma >= 0.0)) {
    throw bus::ConfigError("--bias-sigma " + records::formatNumber(o.bias_sigma) + " must be >= 0");
  }
  c.bias_sigma(o.bias_sigma);
  if (!o.fusion.empty())
    c.fusion(enumOption<navbus::FusionStructure>("fusion", o.fusion, "FUSION_"));
  if (!o.mode.empty()) c.mode(enumOption<navbus::FilterMode>("mode", o.mode, "MODE_"));
  if (o.issuer.empty() || o.issuer.size() > 64) {
    throw bus::ConfigError("--issuer '" + o.issuer + "' must have 1 to 64 characters");
  }
  c.issuer(o.issuer);
  c.run_id(run_id_ns);
  return c;
}

int runCommandCommand(const bus::Participant::Options& participant, const CommandOptions& o,
                      bus::ShutdownSignal& shutdown) {
  const auto run_id =
      static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     std::chrono::system_clock::now().time_since_epoch())
                                     .count());
  const navbus::FilterCommand command = buildCommand(o, run_id);
  bus::Participant p(participant, shutdown);
  auto writer = p.createWriter<navbus::FilterCommandPubSubType>(bus::topic::kFilterCommand,
                                                                bus::profile::kDecisionWriter);
  if (!spinUntil(p, o.match_timeout_s, [&] { return writer.matchedReaders() > 0; })) {
    spdlog::error("no reader of {} (is navbus-filter running on this domain?) within {} s",
                  bus::topic::kFilterCommand, o.match_timeout_s);
    p.finish();
    return bus::kExitRuntimeError;
  }
  if (!writer.write(command)) {
    p.finish();
    return bus::kExitRuntimeError;
  }
  const auto timeout = eprosima::fastrtps::Duration_t(o.match_timeout_s);
  const bool acknowledged =
      writer.raw()->wait_for_acknowledgments(timeout) == ReturnCode_t::RETCODE_OK;
  std::printf("%s", records::textOf(command).c_str());
  if (acknowledged) {
    std::printf(
        "acknowledged by %zu reader(s); the filter's log and summary say whether it was "
        "applied or refused\n",
        writer.matchedReaders());
  } else {
    spdlog::error("the command was not acknowledged within {} s", o.match_timeout_s);
  }
  p.finish();
  return acknowledged ? bus::kExitOk : bus::kExitRuntimeError;
}

}  // namespace navbus::tool
