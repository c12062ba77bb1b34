// Evaluation of the fault pipeline in Monte Carlo runs (`navbus montecarlo --fault-manager`):
// per run, the first detection after the scenario's injected fault is compared with it
// (detection time, INS-vs-GNSS class, satellite or sensor axis, magnitude); detections before
// the fault, or in a fault-free scenario, are false alarms.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "navbus/evaluation/offline_runner.hpp"
#include "navbus/sim/faults.hpp"

namespace navbus::evaluation {

/// How one run's fault was handled.
struct FaultRunOutcome {
  std::uint64_t seed{0};
  bool detected{false};
  double detection_s{0.0};     ///< data time of the first detection after the fault [s from start]
  double onset_s{0.0};         ///< its estimated onset [s from start]
  bool class_correct{false};   ///< INS vs GNSS
  bool source_correct{false};  ///< satellite, or sensor and axis, named first
  bool ambiguous{false};       ///< the decision says ambiguous
  bool shape_correct{false};   ///< a ramp decided as a ramp (steps: always)
  bool truth_among_candidates{false};    ///< the true source is one of the decision's candidates
  double magnitude_error{0.0};           ///< relative, (decided - true) / true, for the true source
  double commanded_error{std::nan("")};  ///< relative error of the compensation commanded, if any
  int false_alarms{0};                   ///< detections before the fault (all, if fault-free)
  int decisions{0};                      ///< every decision of the run, any detector
  /// Decision -> the position error is back inside the 3-sigma envelope (every axis, the
  /// filter's own sigma: the fault-free runs are consistent) and stays there 30 s; NaN: never.
  double recovery_s{std::nan("")};
  std::string decided;  ///< text of the first detection after the fault
  /// The unit (or receiver, satellite) first named after the fault by a decision that is not
  /// ambiguous (the lanes' "lanes" decision between two suspects included) [s from start];
  /// NaN: never.
  double named_s{std::nan("")};
  bool named_correct{false};  ///< ... and it was the faulty one
};

/// Writes the GLR's statistic per accepted epoch (time_gps_ns, statistic, threshold,
/// onset_epochs_ago, detected) as CSV; false if the file could not be written.
bool writeGlrCsv(const std::string& path,
                 const std::vector<fault_manager::GlrEpochStatistic>& trace);

/// The first fault of the schedule that a GLR can detect (IMU bias step or pseudorange ramp).
std::optional<sim::Fault> detectableFault(const sim::FaultSchedule& schedule);
/// parity.csv: the parity test's statistics every 100 ms (OfflineResult::parity_trace).
bool writeParityCsv(const std::string& path, const std::vector<OfflineResult::ParityEpoch>& trace);

/// Compares the run's decisions and commands with the fault.
FaultRunOutcome evaluateRun(const OfflineResult& r, const std::optional<sim::Fault>& fault,
                            std::int64_t start_ns, std::uint64_t seed);

/// Prints the per-case table (mean/min/max detection time, shares isolated, magnitude error,
/// false alarms, false-alarm rate per hour of data).
void printFaultTable(const std::string& label, const std::optional<sim::Fault>& fault,
                     const std::vector<FaultRunOutcome>& runs, double hours_per_run);

}  // namespace navbus::evaluation
