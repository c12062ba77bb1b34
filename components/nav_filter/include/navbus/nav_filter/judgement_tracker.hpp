// When a fault manager's progress report counts: it says every diagnostics epoch up to a time
// is judged and names the latest command it had sent by then. Commands and reports travel on
// different writers, which DDS does not order with each other, so a report counts only once
// that command has arrived too; until then it is held (the latest report only: each one
// supersedes the earlier ones). Pure logic.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include <navbus_idl/Fault.h>

namespace navbus::nav_filter {

class JudgementTracker {
 public:
  /// A report for this filter: the data time judged, if the report counts now.
  std::optional<std::int64_t> onProgress(const navbus::FaultMonitorProgress& report);
  /// A command arrived (any issuer): the held report's time, if it counts now.
  std::optional<std::int64_t> onCommand(const navbus::FilterCommand& command);

  /// The data started over at an earlier time (a new run): how far the IMU data is judged
  /// starts over too (the commands seen are kept: a report may name one of them).
  void newRun() {
    imu_judged_ns_ = 0;
    gnss_judged_ns_ = 0;
    held_.reset();
  }
  std::uint64_t reports() const { return reports_; }
  /// How far the released reports say the IMU data is judged (imu_judged_up_to_gps_ns; 0:
  /// no parity test).
  std::int64_t imuJudged() const { return imu_judged_ns_; }
  /// How far the released reports say the receivers' epochs are judged
  /// (gnss_judged_up_to_gps_ns; 0: no cross-receiver test).
  std::int64_t gnssJudged() const { return gnss_judged_ns_; }
  /// Reports that arrived before the command they name (held until it came).
  std::uint64_t heldForCommand() const { return held_for_command_; }

 private:
  std::optional<std::int64_t> release();

  using Run = std::pair<std::string, std::uint64_t>;  ///< issuer, run_id
  std::map<Run, std::uint64_t> latest_command_id_;    ///< per issuer run
  std::optional<navbus::FaultMonitorProgress> held_;
  std::uint64_t reports_{0};
  std::int64_t imu_judged_ns_{0};
  std::int64_t gnss_judged_ns_{0};
  std::uint64_t held_for_command_{0};
};

}  // namespace navbus::nav_filter
