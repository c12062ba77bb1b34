#include "navbus/tool/command.hpp"

#include <algorithm>
#include <chrono>
#include <optional>

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

namespace {

/// The filter's answer to `c`, as the operator reads it.
std::string outcomeText(const navbus::FilterCommandOutcome& o) {
  std::string text =
      "vehicle " + std::to_string(o.vehicle_id()) + ": " + records::enumName(o.outcome());
  if (o.outcome() == navbus::OUTCOME_REFUSED) {
    text += std::string(" (") + records::enumName(o.reason()) + ")";
  }
  if (o.detail().size() > 0) text += ": " + o.detail().to_string();
  return text;
}

bool answers(const navbus::FilterCommandOutcome& o, const navbus::FilterCommand& c) {
  return o.vehicle_id() == c.vehicle_id() && o.command_id() == c.command_id() &&
         o.issuer() == c.issuer() && o.run_id() == c.run_id();
}

}  // namespace

int runCommandCommand(const bus::Participant::Options& participant, const CommandOptions& o,
                      bus::ShutdownSignal& shutdown) {
  const auto run_id =
      static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     std::chrono::system_clock::now().time_since_epoch())
                                     .count());
  const navbus::FilterCommand command = buildCommand(o, run_id);
  bus::Participant p(participant, shutdown);
  std::optional<navbus::FilterCommandOutcome> outcome;
  p.subscribe<navbus::FilterCommandOutcomePubSubType>(
      bus::topic::kCommandOutcome, bus::profile::kDecisionReader,
      [&](const navbus::FilterCommandOutcome& m, const auto&) {
        if (!outcome && answers(m, command)) outcome = m;
      });
  auto writer = p.createWriter<navbus::FilterCommandPubSubType>(bus::topic::kFilterCommand,
                                                                bus::profile::kDecisionWriter);
  if (!spinUntil(p, o.match_timeout_s, [&] {
        return writer.matchedReaders() >= std::max<std::uint32_t>(1, o.min_readers);
      })) {
    spdlog::error(
        "no reader of {} (is navbus-filter running on this domain?) within {} s ({} of {} "
        "matched)",
        bus::topic::kFilterCommand, o.match_timeout_s, writer.matchedReaders(), o.min_readers);
    p.finish();
    return bus::kExitRuntimeError;
  }
  if (!writer.write(command)) {
    p.finish();
    return bus::kExitRuntimeError;
  }
  std::printf("%s", records::textOf(command).c_str());
  // The command is durable: a filter whose reader matches later still gets it while this waits.
  const bool answered = spinUntil(p, o.match_timeout_s, [&] { return outcome.has_value(); });
  p.finish();
  if (!answered) {
    spdlog::error(
        "no answer from the filter of vehicle {} on {} within {} s (read by {} reader(s))",
        command.vehicle_id(), bus::topic::kCommandOutcome, o.match_timeout_s,
        writer.matchedReaders());
    return bus::kExitRuntimeError;
  }
  std::printf("%s\n", outcomeText(*outcome).c_str());
  return outcome->outcome() == navbus::OUTCOME_REFUSED ? bus::kExitRuntimeError : bus::kExitOk;
}

}  // namespace navbus::tool
