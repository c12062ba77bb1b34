#include "navbus/nav_filter/command_gate.hpp"

#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

namespace navbus::nav_filter {

CommandGate::CommandGate(const FilterConfig& config, bus::StreamCounters& topic_counters,
                         OutcomeSink outcome_sink)
    : vehicle_id_(config.vehicle_id),
      imu_id_(config.imu.id),
      receiver_id_(config.gnss_observations
                       ? std::optional<std::uint32_t>(config.gnss_observations->id)
                       : std::nullopt),
      second_receiver_id_(config.second_gnss_receiver_id),
      issuers_(config.command_issuers),
      issuer_identities_(config.issuer_identities),
      max_accel_compensation_mps2_(config.max_accel_compensation_mps2),
      max_gyro_compensation_radps_(config.max_gyro_compensation_radps),
      topic_counters_(topic_counters),
      outcome_sink_(std::move(outcome_sink)) {}

void CommandGate::report(const navbus::FilterCommand& c, bool applied, navbus::RejectReason reason,
                         const std::string& detail) {
  if (applied) {
    ++counters_.applied;
    ++topic_counters_.accepted;
  } else {
    ++counters_.refused;
    ++topic_counters_.rejected[reason];
  }
  if (!outcome_sink_) return;
  navbus::FilterCommandOutcome o;
  o.vehicle_id(vehicle_id_);
  o.command_id(c.command_id());
  o.issuer(c.issuer());
  o.run_id(c.run_id());
  o.kind(c.kind());
  const bool clamped =
      applied && clamped_ &&
      *clamped_ == std::make_tuple(c.issuer().to_string(), c.run_id(), c.command_id());
  o.outcome(!applied ? navbus::OUTCOME_REFUSED
                     : (clamped ? navbus::OUTCOME_CLAMPED : navbus::OUTCOME_APPLIED));
  o.reason(applied ? navbus::REJECT_NOT_APPLICABLE : reason);
  // The IDL: the field and value refused or clamped; empty when applied as sent.
  o.detail((clamped ? clamped_detail_ : (applied ? std::string() : detail)).substr(0, 160));
  outcome_sink_(o);
}

bool CommandGate::authorized(const navbus::FilterCommand& c,
                             const std::optional<std::string>& writer_identity) {
  const std::string issuer = c.issuer().to_string();
  if (std::find(issuers_.begin(), issuers_.end(), issuer) == issuers_.end()) {
    report(c, false, navbus::REJECT_UNAUTHORIZED, "issuer '" + issuer + "' not in command_issuers");
    ++counters_.unauthorized;
    spdlog::warn(
        "command {} (kind {}) from '{}' refused: not a configured issuer "
        "(command_issuers); {} refused so far",
        c.command_id(), static_cast<int>(c.kind()), issuer, counters_.unauthorized);
    return false;
  }
  if (writer_identity && *writer_identity != issuer_identities_.at(issuer)) {
    report(c, false, navbus::REJECT_UNAUTHORIZED,
           "written by identity '" + *writer_identity + "', not '" + issuer_identities_.at(issuer) +
               "'");
    ++counters_.impersonated;
    spdlog::warn(
        "command {} (kind {}) claims issuer '{}' but was written by identity '{}' (expected "
        "'{}', issuer_identities): refused; {} refused so far",
        c.command_id(), static_cast<int>(c.kind()), issuer, *writer_identity,
        issuer_identities_.at(issuer), counters_.impersonated);
    return false;
  }
  return true;
}

bool CommandGate::refuseIfStale(const navbus::FilterCommand& c, std::int64_t first_input_ns) {
  const auto time_ns = static_cast<std::int64_t>(c.time_gps_ns());
  if (time_ns == 0 || (first_input_ns >= 0 && time_ns >= first_input_ns)) return false;
  report(c, false, navbus::REJECT_STALE,
         fmt::format("time_gps_ns {} before this run's first input", time_ns));
  ++counters_.stale;
  spdlog::warn(
      "command {} (kind {}, decision {}) from '{}' refused: stale, about data at {:.3f} s, "
      "before this run's first input{}; {} stale so far",
      c.command_id(), static_cast<int>(c.kind()), c.decision_id(), c.issuer(),
      1e-9 * static_cast<double>(time_ns),
      first_input_ns < 0 ? " (none yet)"
                         : fmt::format(" at {:.3f} s", 1e-9 * static_cast<double>(first_input_ns)),
      counters_.stale);
  return true;
}

std::optional<std::string> CommandGate::otherImu(const navbus::FilterCommand& c) const {
  // 0 is this filter's IMU (the GLR's and an operator's commands); a redundant unit's
  // instrument (the parity detector's) is another IMU's, not this filter's to fail.
  if (c.sensor_id() == 0 || c.sensor_id() == imu_id_) return std::nullopt;
  return fmt::format("sensor_id {} is not this filter's IMU (imu.id {})", c.sensor_id(), imu_id_);
}

std::optional<std::string> CommandGate::check(const navbus::FilterCommand& c) const {
  switch (c.kind()) {
    case navbus::CMD_SUSPECT_SENSOR_AXIS:  // the lanes' (lane_set.hpp), never one filter's
      return fmt::format("IMU {} as a suspect: this filter has no lanes to compare (lanes:)",
                         c.sensor_id());
    case navbus::CMD_EXCLUDE_SATELLITE:
    case navbus::CMD_READMIT_SATELLITE:
      if (c.sv_id() < 1 || c.sv_id() > 32) return fmt::format("sv_id {} outside 1..32", c.sv_id());
      return std::nullopt;
    case navbus::CMD_FAIL_SENSOR_AXIS:
    case navbus::CMD_RESTORE_SENSOR_AXIS:
      if (auto other = otherImu(c)) return other;
      if (c.sensor() != navbus::SOURCE_ACCELEROMETER && c.sensor() != navbus::SOURCE_GYRO)
        return fmt::format("sensor {} is not an accelerometer or gyro",
                           static_cast<int>(c.sensor()));
      if (c.axis() > 2) return fmt::format("axis {} outside 0..2", c.axis());
      return std::nullopt;
    case navbus::CMD_COMPENSATE_BIAS:
      if (c.sensor() == navbus::SOURCE_RECEIVER_CLOCK) return checkReceiverClock(c);
      [[fallthrough]];
    case navbus::CMD_RELEARN_BIAS: {
      if (auto other = otherImu(c)) return other;
      if (c.sensor() != navbus::SOURCE_ACCELEROMETER && c.sensor() != navbus::SOURCE_GYRO)
        return fmt::format("sensor {} is not an accelerometer or gyro",
                           static_cast<int>(c.sensor()));
      if (c.axis() > 2) return fmt::format("axis {} outside 0..2", c.axis());
      const bool accel = c.sensor() == navbus::SOURCE_ACCELEROMETER;
      const double limit = compensationLimit(accel);
      // A re-learned bias is unknown up to bias_sigma; one beyond the limit is re-learned up to
      // the limit (relearnSigma), the largest bias the filter is configured to take.
      const bool relearn = c.kind() == navbus::CMD_RELEARN_BIAS;
      if (!std::isfinite(c.bias_sigma()) || c.bias_sigma() < 0.0 ||
          (c.bias_sigma() > limit && !relearn))
        return fmt::format("bias_sigma {} outside 0..{}", c.bias_sigma(), limit);
      if (!std::isfinite(c.bias()) || std::abs(c.bias()) > limit)
        return fmt::format(
            "bias {} outside +-{} ({})", c.bias(), limit,
            accel ? "m/s^2, max_accel_compensation_mg" : "rad/s, max_gyro_compensation_deg_per_h");
      return std::nullopt;
    }
    default:
      return std::nullopt;
  }
}

std::optional<std::string> CommandGate::checkReceiverClock(const navbus::FilterCommand& c) const {
  if (!receiver_id_)
    return fmt::format("sensor_id {}: this filter fuses no receiver's pseudoranges", c.sensor_id());
  if (c.sensor_id() != *receiver_id_ &&
      c.sensor_id() != second_receiver_id_.value_or(*receiver_id_))
    return fmt::format(
        "sensor_id {} is not a receiver this filter fuses (gnss_observations.id {}{})",
        c.sensor_id(), *receiver_id_,
        second_receiver_id_ ? fmt::format(", second_id {}", *second_receiver_id_) : "");
  if (!std::isfinite(c.bias())) return fmt::format("bias {} is not finite", c.bias());
  if (!std::isfinite(c.bias_sigma()) || c.bias_sigma() < 0.0)
    return fmt::format("bias_sigma {} outside 0..inf", c.bias_sigma());
  return std::nullopt;
}

double CommandGate::relearnSigma(const navbus::FilterCommand& c) {
  const double limit = compensationLimit(c.sensor() == navbus::SOURCE_ACCELEROMETER);
  if (c.bias_sigma() <= limit) return c.bias_sigma();
  ++counters_.relearn_clamped;
  clamped_ = std::make_tuple(c.issuer().to_string(), c.run_id(), c.command_id());
  clamped_detail_ =
      fmt::format("bias_sigma {} clamped to the compensation limit {}", c.bias_sigma(), limit);
  spdlog::warn(
      "command {} from '{}': re-learn bias_sigma {} beyond the compensation limit {} (recovery."
      "max_{}_compensation): re-learned up to the limit; {} clamped so far",
      c.command_id(), c.issuer(), c.bias_sigma(), limit,
      c.sensor() == navbus::SOURCE_ACCELEROMETER ? "accel" : "gyro", counters_.relearn_clamped);
  return limit;
}

}  // namespace navbus::nav_filter
