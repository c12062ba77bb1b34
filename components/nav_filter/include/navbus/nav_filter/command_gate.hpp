// Who may command navbus-filter, and what: the policy a FilterCommand passes before the
// pipeline applies it. The issuer must be configured (command_issuers) and, under DDS Security,
// be the identity that wrote the command (issuer_identities); a command about data before this
// run's first input is stale; every field is range-checked, a bias against the compensation
// limits (recovery.max_*_compensation), and a re-learn's sigma is clamped to them. Every
// command ends counted once in the health of the command topic, accepted or rejected with its
// reason, and every refusal is logged with the field and value; the issuer is answered with a
// FilterCommandOutcome (applied, clamped or refused, with the field and value) through the
// outcome sink. DDS-free: it reads the IDL
// command, the pipeline feeds it and applies what passed (filter_pipeline.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <navbus_idl/Fault.h>

#include "navbus/bus/health.hpp"
#include "navbus/nav_filter/filter_config.hpp"

namespace navbus::nav_filter {

/// What the gate counted (the pipeline's summary shows them).
struct CommandCounters {
  std::uint64_t applied{0};
  std::uint64_t refused{0};
  std::uint64_t unauthorized{0};     ///< of those refused: not from a configured issuer
  std::uint64_t impersonated{0};     ///< of those refused: issuer not the writer's identity
  std::uint64_t stale{0};            ///< of those refused: about data before the first input
  std::uint64_t late{0};             ///< arrived after their data time was processed
  std::uint64_t relearn_clamped{0};  ///< CMD_RELEARN_BIAS applied at the compensation limit
};

class CommandGate {
 public:
  using OutcomeSink = std::function<void(const navbus::FilterCommandOutcome&)>;

  /// `topic_counters`: the health of the command topic (accepted, rejected by reason).
  CommandGate(const FilterConfig& config, bus::StreamCounters& topic_counters,
              OutcomeSink outcome_sink = {});

  /// The command is for this filter's vehicle (others are not ours: ignored, not counted).
  bool addressedToThisVehicle(const navbus::FilterCommand& c) const {
    return c.vehicle_id() == vehicle_id_;
  }
  /// The issuer is configured and, under DDS Security, is the identity that wrote the command
  /// (`writer_identity`; nullopt where nobody is authenticated); otherwise the command is
  /// refused, logged and counted.
  bool authorized(const navbus::FilterCommand& c,
                  const std::optional<std::string>& writer_identity);
  /// Refuses, logs and counts a command about data before `first_input_ns` (the data time of
  /// this run's first processed input, -1: none yet); true if it was stale.
  bool refuseIfStale(const navbus::FilterCommand& c, std::int64_t first_input_ns);
  /// Why the command's fields cannot be applied (field and value), or nothing.
  std::optional<std::string> check(const navbus::FilterCommand& c) const;
  /// Why a receiver clock's compensation cannot be applied (another receiver than the fused
  /// one, a value not finite), or nothing.
  std::optional<std::string> checkReceiverClock(const navbus::FilterCommand& c) const;
  /// Why an IMU-axis command names another IMU than this filter's (sensor_id), or nothing.
  std::optional<std::string> otherImu(const navbus::FilterCommand& c) const;
  /// A re-learn's bias_sigma, at most the compensation limit (counted and logged when clamped;
  /// the command's outcome then says OUTCOME_CLAMPED).
  double relearnSigma(const navbus::FilterCommand& c);

  /// The command's outcome: counted in the health of the command topic (accepted, or rejected
  /// for `reason`) and answered to its issuer; `detail` names the field and value refused.
  void report(const navbus::FilterCommand& c, bool applied,
              navbus::RejectReason reason = navbus::REJECT_NOT_APPLICABLE,
              const std::string& detail = {});
  /// A command that arrived after its data time had been processed (applied at once).
  void countLate() { ++counters_.late; }
  const CommandCounters& counters() const { return counters_; }

 private:
  /// The compensation limit of the accelerometers [m/s^2] or the gyros [rad/s].
  double compensationLimit(bool accel) const {
    return accel ? max_accel_compensation_mps2_ : max_gyro_compensation_radps_;
  }

  std::uint32_t vehicle_id_;
  std::uint32_t imu_id_;                      ///< this filter's IMU (FilterConfig imu.id)
  std::optional<std::uint32_t> receiver_id_;  ///< its receiver (gnss_observations.id), if any
  std::optional<std::uint32_t> second_receiver_id_;  ///< a second fused receiver (second_id)
  std::vector<std::string> issuers_;
  std::map<std::string, std::string> issuer_identities_;
  double max_accel_compensation_mps2_;
  double max_gyro_compensation_radps_;
  bus::StreamCounters& topic_counters_;
  OutcomeSink outcome_sink_;
  CommandCounters counters_;
  /// The latest command whose re-learn sigma was clamped (issuer, run, id), and by what.
  std::optional<std::tuple<std::string, std::uint64_t, std::uint64_t>> clamped_;
  std::string clamped_detail_;
};

}  // namespace navbus::nav_filter
