#include "navbus/nav_filter/engine_commands.hpp"

#include "navbus/nav_filter/solution_messages.hpp"

namespace navbus::nav_filter {

bool applyEngineCommand(core::NavigationEngine& engine, const navbus::FilterCommand& c,
                        double relearn_sigma) {
  return applyEngineCommand(engine, c, relearn_sigma, 0);
}

bool applyEngineCommand(core::NavigationEngine& engine, const navbus::FilterCommand& c,
                        double relearn_sigma, int receiver) {
  switch (c.kind()) {
    case navbus::CMD_EXCLUDE_SATELLITE:
      engine.excludeSatellite(c.sv_id(), toCore(c.scope()));
      return true;
    case navbus::CMD_READMIT_SATELLITE:
      engine.readmitSatellite(c.sv_id(), toCore(c.scope()));
      return true;
    case navbus::CMD_RELEARN_BIAS:
      engine.relearnBias(c.sensor() == navbus::SOURCE_ACCELEROMETER, c.axis(), relearn_sigma);
      return true;
    case navbus::CMD_COMPENSATE_BIAS:
      if (c.sensor() == navbus::SOURCE_RECEIVER_CLOCK) {  // the receiver checked by the gate
        engine.compensateReceiverClock(c.bias(), c.bias_sigma(), receiver);
        return true;
      }
      engine.compensateBias(c.sensor() == navbus::SOURCE_ACCELEROMETER, c.axis(), c.bias(),
                            c.bias_sigma());
      return true;
    case navbus::CMD_FAIL_SENSOR_AXIS:
      engine.failSensorAxis(c.sensor() == navbus::SOURCE_ACCELEROMETER, c.axis());
      return true;
    case navbus::CMD_RESTORE_SENSOR_AXIS:
      engine.restoreSensorAxis(c.sensor() == navbus::SOURCE_ACCELEROMETER, c.axis());
      return true;
    case navbus::CMD_SELECT_FUSION:
      switch (c.fusion()) {
        case navbus::FUSION_CENTRALIZED:
          return engine.selectFusion(core::FusionStructure::kCentralized);
        case navbus::FUSION_FEDERATED:
          return engine.selectFusion(core::FusionStructure::kFederated);
        case navbus::FUSION_ADAPTIVE:
          return engine.selectFusion(core::FusionStructure::kAdaptive);
        default:
          return engine.config().aiding == core::AidingMode::kInertialOnly;
      }
    case navbus::CMD_SELECT_MODE:
      // The aiding mode follows the configured inputs; only the current one is accepted.
      return c.mode() == toIdl(engine.mode());
    case navbus::CMD_RESET:
      engine.reset();
      return true;
    default:
      return false;
  }
}

bool answersFaultWithOnset(const navbus::FilterCommand& c) {
  return c.onset_time_gps_ns() > 0 &&
         (c.kind() == navbus::CMD_EXCLUDE_SATELLITE || c.kind() == navbus::CMD_COMPENSATE_BIAS ||
          c.kind() == navbus::CMD_RELEARN_BIAS || c.kind() == navbus::CMD_FAIL_SENSOR_AXIS);
}

std::int64_t restorePoint(const navbus::FilterCommand& c, std::int64_t onset_margin_ns) {
  // The onset is an estimate: a satellite is excluded from a margin before it (using one
  // satellite fewer for a few seconds costs little); a bias is compensated from the onset
  // itself (earlier would add the bias where there was none).
  const auto onset = static_cast<std::int64_t>(c.onset_time_gps_ns());
  return c.kind() == navbus::CMD_EXCLUDE_SATELLITE ? onset - onset_margin_ns : onset;
}

core::SatelliteScope toCore(navbus::SatelliteScope s) {
  switch (s) {
    case navbus::SCOPE_PSEUDORANGE:
      return core::SatelliteScope::kRange;
    case navbus::SCOPE_PSEUDORANGE_RATE:
      return core::SatelliteScope::kRate;
    default:
      return core::SatelliteScope::kAll;
  }
}

}  // namespace navbus::nav_filter
