// `navbus benchmark real-car`: a real log with GNSS outages. The data set is imported, the
// filter runs causally with the GNSS solutions withheld inside each outage, and the antenna
// positions it gives are scored against the withheld fixed (RTK) epochs: the horizontal error
// at the end of each outage, the largest inside it, the RMS over all outage epochs and the share
// of outage epochs inside the filter's own 3-sigma; and, with GNSS available, the horizontal RMS
// against the fixed epochs it fused. With smoothing, the fixed-interval smoother's positions are
// scored on the same outages. Without outages (`navbus benchmark real-data`) every fixed epoch
// is scored with GNSS; a data set with raw observations is scored beside its own single point
// positioning.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "navbus/importers/dataset.hpp"

namespace navbus::evaluation {

/// One outage [start, end) in GPS seconds of week: a solution epoch t is withheld when
/// start <= t < end (its time stamp as the solution file has it).
struct Outage {
  double start_sow{0.0};
  double end_sow{0.0};
};

/// One outage line `START END` per line, `#` comments; throws bus::ConfigError naming the file
/// and the line.
std::vector<Outage> readOutages(const std::filesystem::path& file);

/// A regular schedule: outages of `length_s` every `period_s` from `first_start_sow` [GPS s of
/// week], as many as end before the log's last epoch.
struct OutageSchedule {
  double length_s{0.0};
  double period_s{0.0};
  double first_start_sow{0.0};
};

/// The schedule's outages up to `last_sow`; throws bus::ConfigError naming the bad value.
std::vector<Outage> outageSchedule(const OutageSchedule& s, double last_sow);

struct RealCarOptions {
  std::string dataset;  ///< data set YAML (config/datasets/)
  std::string filter;   ///< navbus-filter YAML
  std::string outages;  ///< outage list; empty: the schedule, or none
  /// A regular schedule instead of a list; neither: every fixed epoch is scored with GNSS.
  std::optional<OutageSchedule> schedule;
  std::string out_dir;  ///< solution.csv, outages.csv, scores.csv, the recording
  bool smooth{false};   ///< also the smoothed run: smoothed.csv, smoothed_outages.csv
  /// navbus-fault-manager YAML: the fault pipeline (GLR) runs beside the filter and its
  /// decisions act on it (empty: the filter alone). Protection levels, published by a filter
  /// with an `integrity` block, are scored either way.
  std::string fault_manager;
  /// An IMU bias step injected by the import: the benchmark then says when the filter flagged
  /// its solution after the onset, and what it published unflagged before that.
  std::optional<importers::ImuStep> imu_step;
};

int runRealCarBenchmark(const RealCarOptions& o);

}  // namespace navbus::evaluation
