// `navbus-sensor-sim --files DIR`: the scenario's streams as plain CSV files for offline work
// (columns documented in docs/simulation.md): imu.csv, imu_raw.csv, gnss.csv, gnss_fix.csv,
// star_tracker.csv, truth.csv, faults.csv.
#pragma once

#include <filesystem>
#include <fstream>

#include "navbus/sim/scenario_source.hpp"

namespace navbus::sensor_sim {

class FileWriter {
 public:
  /// Creates DIR and the files with their header lines; writes faults.csv at once.
  FileWriter(const std::filesystem::path& dir, const sim::ScenarioConfig& scenario);
  void write(const sim::SensorFrame& frame);
  struct Counts {
    std::uint64_t imu{0}, raw{0}, gnss_epochs{0}, gnss_fixes{0}, star_tracker{0};
  };
  const Counts& counts() const { return counts_; }

 private:
  std::ofstream open(const std::string& name, const std::string& header);

  std::filesystem::path dir_;
  std::ofstream imu_, raw_, gnss_, fix_, star_, truth_;
  Counts counts_;
};

}  // namespace navbus::sensor_sim
