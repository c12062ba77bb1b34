// An IMU's CSV log read through a data set description (dataset.hpp): one sample per line, in
// SI units and the sensor's axes, with its GPS time. A line cut at the very start or end of the
// file (a logger started or stopped mid-line) is reported and skipped; any other malformed line
// is an error naming the file, the line, the column and the text.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "navbus/importers/dataset.hpp"

namespace navbus::importers {

struct ImuSample {
  std::int64_t time_gps_ns{0};
  Eigen::Vector3d specific_force_s_mps2{Eigen::Vector3d::Zero()};  ///< sensor axes
  Eigen::Vector3d rate_s_radps{Eigen::Vector3d::Zero()};           ///< sensor axes
};

struct ImuLog {
  std::vector<ImuSample> samples;
  std::vector<std::string> skipped;  ///< one line per cut line skipped: file, line, why
  std::vector<std::string> notes;    ///< how the times were made
};

/// Throws bus::ConfigError (file, line, column, text) for a malformed line that is not the
/// first or last, for times that do not increase, and for an unreadable time tag.
ImuLog readImuCsv(const ImuCsvDescription& description);

}  // namespace navbus::importers
