// The GLR detector of the fault pipeline (seed 000): runs core::GlrMonitor on the filter's
// diagnostics, turns a detection into a decision (detector "glr": the isolated source, shape,
// statistic, threshold, magnitude, onset and the candidates) and the commands the
// configuration asks for (exclude an isolated satellite, compensate an isolated IMU bias;
// nothing for an ambiguous IMU isolation), and readmits an excluded satellite once its
// residuals pass again for the configured time. Repeated decisions on one source escalate
// once (repeat_guard.hpp): its IMU axes are failed (CMD_FAIL_SENSOR_AXIS), a satellite stays
// excluded.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <navbus_idl/Fault.h>
#include <navbus_idl/Navigation.h>

#include "navbus/core/integrity/glr.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/fault_output.hpp"
#include "navbus/fault_manager/repeat_guard.hpp"

namespace navbus::fault_manager {

/// The GLR's largest statistic at one accepted epoch (seed 000, eq. 13) against its threshold h.
struct GlrEpochStatistic {
  std::int64_t time_ns{0};
  double statistic{0.0};
  double threshold{0.0};
  int onset_epochs_ago{0};  ///< of the largest statistic
  bool detected{false};
};

class GlrDetector {
 public:
  explicit GlrDetector(const GlrDetectorConfig& config);

  /// One validated diagnostics sample of the monitored vehicle, in order. A gap in `seq`
  /// restarts the statistics (the signatures need every epoch). Returns false (and counts)
  /// when the sample does not describe the tightly coupled filter the GLR models.
  bool onDiagnostics(const navbus::FilterDiagnostics& msg, FaultOutput& out);

  /// Another detector (the cross-receiver test) had the filter exclude `sv_id` for good: its
  /// rows, monitored in the diagnostics, leave the GLR's epochs from here (as its own
  /// exclusions' do, without a readmission: that is the other detector's), and the statistics
  /// restart (the filter reconfigured).
  void keepOut(int sv_id);

  struct Counters {
    std::uint64_t epochs{0}, refused{0}, restarts{0};
    std::uint64_t detections{0}, satellites_excluded{0}, biases_compensated{0};
    std::uint64_t ambiguous{0};  ///< IMU isolations not certain: biases re-learned instead
    std::uint64_t readmitted{0};
    std::uint64_t escalated{0};   ///< repeated decisions escalated (repeat_guard.hpp)
    std::uint64_t suppressed{0};  ///< detections of escalated sources not decided again
    double max_statistic{0.0};    ///< largest statistic seen
  };
  const Counters& counters() const { return counters_; }
  const core::GlrMonitor& monitor() const { return glr_; }
  /// The statistic of the latest accepted epoch (kept: a detection resets the monitor).
  const GlrEpochStatistic& latest() const { return latest_; }
  std::string summary() const;

 private:
  void report(const core::GlrResult& r, FaultOutput& out);
  void checkReadmission(FaultOutput& out);
  void removeQuarantinedRows();
  void refine(FaultOutput& out);
  void relearn(const core::GlrResult& r, navbus::FilterCommand c, FaultOutput& out);
  /// What is left once re-learning or compensating has not cured a source.
  void escalate(const core::GlrResult& r, navbus::FilterCommand c, FaultOutput& out);
  navbus::FaultDecision decision(const core::GlrResult& r) const;

  struct Pending {
    bool active{false};
    std::uint32_t decision_id{0};
    std::int64_t onset_ns{0};
  };
  Pending pending_;
  core::GlrResult last_;  ///< isolation at the pending onset, latest epoch

  struct Quarantine {
    int sv_id;
    navbus::SatelliteScope scope;   ///< the measurements excluded
    std::int64_t passing_since_ns;  ///< -1: not passing
    bool permanent{false};          ///< escalated: never readmitted
    bool covers(int sv, bool is_rate) const;
  };

  GlrDetectorConfig config_;
  RepeatGuard repeats_;
  core::GlrMonitor glr_;
  core::GlrEpoch epoch_;
  std::uint64_t last_seq_{0};
  std::vector<Quarantine> quarantine_;
  Counters counters_;
  GlrEpochStatistic latest_;
};

}  // namespace navbus::fault_manager
