// `navbus-sensor-sim --files DIR`: the scenario's streams as plain CSV files for offline work
// (columns documented in docs/simulation.md): imu.csv, imu_raw.csv, gnss.csv, gnss_fix.csv,
// star_tracker.csv, truth.csv, faults.csv; with redundant units imu_units.csv and
// gnss_receivers.csv (the further units' and receivers' data, each row naming its id).
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include "navbus/sim/scenario_source.hpp"

namespace navbus::sensor_sim {

class FileWriter {
 public:
  /// Creates DIR and the files with their header lines; writes faults.csv at once. The ids of
  /// the scenario's further IMU units and receivers (its extra_imus / extra_receivers order)
  /// name their rows.
  FileWriter(const std::filesystem::path& dir, const sim::ScenarioConfig& scenario,
             std::vector<std::uint32_t> extra_imu_ids = {},
             std::vector<std::uint32_t> extra_receiver_ids = {});
  void write(const sim::SensorFrame& frame);
  struct Counts {
    std::uint64_t imu{0}, raw{0}, gnss_epochs{0}, gnss_fixes{0}, star_tracker{0};
    std::uint64_t unit_increments{0};  ///< of the further IMU units, all together
    std::uint64_t receiver_epochs{0};  ///< of the further receivers, all together
  };
  const Counts& counts() const { return counts_; }

 private:
  std::ofstream open(const std::string& name, const std::string& header);
  void writeSatellites(std::ofstream& out, const std::string& prefix, const sim::GnssEpoch& e);
  void writeUnits(const sim::SensorFrame& f);

  std::filesystem::path dir_;
  std::ofstream imu_, raw_, gnss_, fix_, star_, truth_;
  std::vector<std::uint32_t> unit_ids_, receiver_ids_;
  std::ofstream units_, receivers_;  ///< open only with further units / receivers
  Counts counts_;
};

}  // namespace navbus::sensor_sim
