// `navbus import`: a data set (dataset.hpp) into a navbus recording, the CSV files per topic
// that `navbus record` writes and `navbus replay` and `navbus offline --recording` read.
#pragma once

#include <filesystem>
#include <string>

#include "navbus/importers/dataset.hpp"

namespace navbus::importers {

struct ImportReport {
  std::uint64_t imu_samples{0};
  std::uint64_t imu_increments{0};
  std::uint64_t imu_blocks{0};
  std::uint64_t imu_samples_injected{0};   ///< samples the IMU step changed
  std::int64_t imu_step_onset_gps_ns{-1};  ///< the IMU step's onset [ns, GPS time]; -1: none
  std::uint64_t gnss_fixes{0};
  std::uint64_t gnss_epochs{0};  ///< observation epochs written
  std::string text;              ///< what was read, skipped and written, for the user
};

/// Writes the recording into `out_dir` (created). Throws bus::ConfigError for bad input.
ImportReport importDataset(const DatasetDescription& dataset, const std::filesystem::path& out_dir);

}  // namespace navbus::importers
