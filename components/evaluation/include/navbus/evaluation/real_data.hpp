// `navbus rinex`: real GPS observations through navbus's GNSS path. RINEX 2 observation and
// navigation files are read (gnss_data/rinex2.hpp), every epoch is solved by single point
// positioning (core/gnss/single_point_positioning.hpp), and the corrected pseudoranges drive the
// static receiver filter (core/filter/static_receiver_filter.hpp) whose diagnostics go through the
// fault manager's pipeline: the same GLR detector, decisions and commands as on the bus, the
// commands applied back to the filter (satellite exclusion, re-processing from the onset,
// readmission). A ramp can be injected into one satellite's pseudoranges to test detection.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <navbus_idl/Fault.h>
#include <Eigen/Core>

#include "navbus/core/filter/static_receiver_filter.hpp"
#include "navbus/core/gnss/single_point_positioning.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/glr_detector.hpp"
#include "navbus/gnss_data/rinex2.hpp"

namespace navbus::evaluation {

/// A fault added to the raw pseudoranges of one satellite: rate * (t - onset) after onset.
struct RampInjection {
  int sv_id{0};
  double rate_mps{0.0};
  double onset_after_start_s{0.0};  ///< after the first epoch of the file
};

struct RealDataSetup {
  gnss_data::RinexObservationFile obs;
  gnss_data::RinexNavigationFile nav;
  std::string observable{"C1"};
  Eigen::Vector3d reference_ecef_m{Eigen::Vector3d::Zero()};  ///< for the error columns
  core::SinglePointConfig spp;
  core::StaticReceiverTuning filter;
  std::optional<fault_manager::FaultManagerConfig> fault_manager;
  std::optional<RampInjection> ramp;
};

struct RealDataEpoch {
  std::int64_t time_ns{0};
  int satellites{0};  ///< GPS satellites with the observable
  bool fix_valid{false};
  int fix_used{0};
  Eigen::Vector3d fix_ecef_m{Eigen::Vector3d::Zero()};
  double fix_clock_bias_m{0.0};
  Eigen::Vector3d fix_error_ned_m{Eigen::Vector3d::Zero()};  ///< fix - reference, NED
  bool filtered{false};
  int filter_rows_used{0};
  Eigen::Vector3d filter_error_ned_m{Eigen::Vector3d::Zero()};  ///< filter - reference, NED
  Eigen::Vector3d filter_sigma_ned_m{Eigen::Vector3d::Zero()};
};

struct RealDataResult {
  std::vector<RealDataEpoch> epochs;
  std::uint64_t fixes{0}, no_fix{0};
  /// Satellites not used by the fix, by reason, summed over epochs.
  std::uint64_t below_mask{0}, no_ephemeris{0}, bad_range{0}, other_systems{0}, missing{0};
  std::vector<navbus::FaultDecision> decisions;
  std::vector<navbus::FilterCommand> commands;
  std::uint64_t commands_not_applicable{0};  ///< kinds a static GNSS filter has no use for
  std::uint64_t reprocessings{0};            ///< re-runs of the filter from an onset
  std::uint64_t injected_epochs{0};          ///< pseudoranges the ramp injection changed
  std::string fault_summary;
  double max_glr_statistic{0.0};
  std::vector<fault_manager::GlrEpochStatistic> glr_trace;  ///< every epoch the GLR accepted
};

RealDataResult runRealData(const RealDataSetup& setup);

struct RealDataOptions {
  std::string obs, nav, out_dir;
  std::string fault_manager;      ///< navbus-fault-manager YAML (GLR); empty: no monitor
  std::vector<double> reference;  ///< x,y,z ECEF [m]; empty: the header's APPROX POSITION
  std::vector<double> ramp;       ///< sv,rate_mps,onset_s; empty: no injection
};

/// Reads the files, runs, writes fixes.csv (and decisions.csv, commands.csv with a fault
/// manager) and prints the summary; returns an exit code.
int runRealDataCommand(const RealDataOptions& o);

}  // namespace navbus::evaluation
