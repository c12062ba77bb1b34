// A navbus recording (what `navbus record` or `navbus import` writes: a CSV file per topic)
// run through navbus-filter's pipeline without DDS, and the fault manager's when configured:
// the samples go in in data-time order, the pipeline's clock is the data time. Over the bus,
// `navbus replay` of the same recording into the participants gives the same solutions.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <navbus_idl/Fault.h>
#include <navbus_idl/Navigation.h>

#include "navbus/core/filter/rts_smoother.hpp"
#include "navbus/core/integrity/consistency_monitor.hpp"
#include "navbus/core/integrity/fix_innovation_log.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/nav_filter/filter_config.hpp"

namespace navbus::evaluation {

struct RecordingSetup {
  std::filesystem::path dir;
  nav_filter::FilterConfig filter;
  std::optional<fault_manager::FaultManagerConfig> fault_manager;
  /// GNSS fixes for which this is true are left out (GNSS outages of a benchmark); counted.
  std::function<bool(const navbus::GnssFix&)> withhold{};
  /// Post-processing: a fixed-interval (RTS) smoother runs backward over the forward
  /// filter's records (core/filter/rts_smoother.hpp).
  bool smooth{false};
};

struct RecordingResult {
  std::uint64_t solutions{0};
  std::string inputs;  ///< what the recording held, per topic
  std::uint64_t fixes_withheld{0};
  std::string summary;  ///< the filter pipeline's counters
  /// The filter's test of its own innovations over the run (mean NIS per row: nis_sum / rows).
  core::ConsistencyCounters consistency;
  /// The fixes' position and velocity rows' normalized innovations squared.
  core::InnovationStatistics fix_position_nis, fix_velocity_nis;
  std::string fault_summary;
  std::vector<navbus::FaultDecision> decisions;
  std::vector<navbus::FilterCommand> commands;
  /// Every lane's solution at every time (filter `lanes:`; empty without).
  std::vector<navbus::LaneSolution> lane_solutions;
  /// With a fault manager: the adaptive noise scales of the last diagnostics the filter
  /// published (empty when its noise does not adapt).
  std::vector<navbus::NoiseScale> last_noise_scales;
  /// ... and its scale on the process noise (1 when it does not adapt; 0: no diagnostics).
  double last_process_noise_scale{0.0};
  /// With RecordingSetup::smooth: one epoch per forward record, and what the smoother says.
  std::vector<core::SmoothedEpoch> smoothed;
  std::string smoother_summary;
  /// Every fused GNSS fix's innovations (core/integrity/fix_innovation_log.hpp).
  std::vector<core::FixInnovation> fix_innovations;
};

using RecordedSolutionHook = std::function<void(const navbus::NavigationSolution&)>;

/// Throws bus::ConfigError when the directory holds no recorded sensor topic or a file does
/// not read as its topic.
RecordingResult runRecording(const RecordingSetup& setup, const RecordedSolutionHook& hook = {});

/// A data set (its YAML) imported into out_dir/recording, with the filter configuration read
/// from its YAML: the start of the calibration commands. `import_text` is the import's report.
struct ImportedRun {
  RecordingSetup setup;
  std::string import_text;
};
ImportedRun importForRun(const std::string& dataset_yaml, const std::string& filter_yaml,
                         const std::filesystem::path& out_dir);

struct RecordingOptions {
  std::string recording;
  std::string filter;
  std::string fault_manager;
  std::string out_dir;
  bool smooth{false};       ///< also write smoothed.csv
  bool innovations{false};  ///< also write innovations.csv
};

/// The smoothed epochs as CSV (smoothed.csv): GPS time [s of week], the IMU's position, velocity
/// and attitude, their smoothed 1-sigma, and whether the epoch is smoothed.
void writeSmoothedCsv(const std::filesystem::path& file,
                      const std::vector<core::SmoothedEpoch>& epochs);

/// The fused fixes' innovations as CSV (innovations.csv): GPS time [s of week], the filter's
/// NED velocity after the fix, and per NED row the position and velocity innovation (predicted
/// minus measured) with its sigma sqrt(H P- H^T + R); the along- and cross-track position
/// innovations (the filter's horizontal course; 0 below 1 m/s), and the consistency monitor's
/// verdict.
void writeFixInnovationsCsv(const std::filesystem::path& file,
                            const std::vector<core::FixInnovation>& fixes);

/// `navbus offline --recording`: writes solution.csv (and decisions.csv, commands.csv with a
/// fault manager) into out_dir; returns an exit code.
int runRecordingCommand(const RecordingOptions& o);

}  // namespace navbus::evaluation
