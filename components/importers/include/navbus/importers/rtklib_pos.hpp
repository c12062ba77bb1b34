// RTKLIB solution files (.pos, the "solution format" of rnx2rtkp, rtkpost, convbin and RTKLIB's
// stream server) read into navbus GNSS fixes. The last `%` header line names the columns; time
// stamps are GPST (calendar or week and seconds), positions geodetic (lat/lon/height), velocity
// columns (vn ve vu and their sigmas) optional. Each epoch's quality (Q) chooses how its sigmas
// are used (dataset.hpp, QualityUse).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <navbus_idl/Gnss.h>

#include "navbus/importers/dataset.hpp"

namespace navbus::importers {

struct PosLog {
  std::vector<navbus::GnssFix> fixes;
  std::vector<std::uint8_t> quality;  ///< RTKLIB Q of each fix (1 fix, 2 float, ...)
  std::array<std::uint64_t, kQualityNames.size()> epochs_by_quality{};    ///< read, per Q
  std::array<std::uint64_t, kQualityNames.size()> left_out_by_quality{};  ///< use: false
  bool has_velocity{false};
};

/// Throws bus::ConfigError naming the file, the line, the column and the text.
PosLog readPosFile(const PosDescription& description);

}  // namespace navbus::importers
