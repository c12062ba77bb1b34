// RTKLIB (demo5) time-tag files: what a logger wrote beside a stream to say when each part of
// it arrived. Layout (RTKLIB demo5, stream.c): a 60-byte text header starting "TIMETAG
// RTKLIB", the logger's tick at the start [ms, uint32 little-endian], the GPS time of the start
// (uint32 seconds since 1970-01-01 on the GPS time scale, then a double fraction of a second),
// then one record per write: tick since the start [ms, uint32] and the byte offset of the write
// in the logged stream [uint32].
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace navbus::importers {

struct TimeTag {
  std::int64_t start_gps_ns{0};  ///< GPS time of the start [ns since 1980-01-06 00:00:00]
  std::uint32_t start_tick_ms{0};
  struct Record {
    std::uint32_t tick_ms;  ///< since the start
    std::uint32_t offset;   ///< byte offset in the logged stream
  };
  std::vector<Record> records;
  /// The last record's tick [ms since the start]: how long the logger ran.
  std::uint32_t lastTickMs() const { return records.empty() ? 0 : records.back().tick_ms; }
};

/// Throws bus::ConfigError naming the file and what is wrong with it.
TimeTag readTimeTag(const std::filesystem::path& path);

/// GPS seconds since 1980-01-06 of a count of seconds since 1970-01-01 on the GPS time scale.
inline constexpr std::int64_t kGpsEpochFromUnixEpochS = 315'964'800;

}  // namespace navbus::importers
