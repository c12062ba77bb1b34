#include "navbus/importers/rtklib_time_tag.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "navbus/bus/config.hpp"

namespace navbus::importers {

namespace {

constexpr std::size_t kHeaderBytes = 60;
constexpr const char* kMagic = "TIMETAG RTKLIB";
constexpr std::size_t kStartBytes = 4 + 4 + 8;  // tick, seconds, fraction
constexpr std::size_t kRecordBytes = 8;

template <class T>
T readLittleEndian(const std::string& bytes, std::size_t at) {
  T value;
  static_assert(sizeof(T) == 4 || sizeof(T) == 8);
  std::memcpy(&value, bytes.data() + at, sizeof(T));  // x86/ARM little-endian hosts
  return value;
}

}  // namespace

TimeTag readTimeTag(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw bus::ConfigError(path.string() + ": cannot be read");
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  if (bytes.size() < kHeaderBytes + kStartBytes ||
      bytes.compare(0, std::strlen(kMagic), kMagic) != 0)
    throw bus::ConfigError(path.string() + ": not an RTKLIB time-tag file (no '" +
                           std::string(kMagic) + "' header)");
  const std::size_t body = bytes.size() - kHeaderBytes - kStartBytes;
  if (body % kRecordBytes != 0)
    throw bus::ConfigError(path.string() + ": " + std::to_string(body) +
                           " bytes of records, not a whole number of 8-byte records");
  TimeTag tag;
  tag.start_tick_ms = readLittleEndian<std::uint32_t>(bytes, kHeaderBytes);
  const auto seconds = readLittleEndian<std::uint32_t>(bytes, kHeaderBytes + 4);
  const auto fraction = readLittleEndian<double>(bytes, kHeaderBytes + 8);
  if (!(fraction >= 0.0 && fraction < 1.0))
    throw bus::ConfigError(path.string() + ": start time fraction " + std::to_string(fraction) +
                           " is not in [0, 1)");
  if (seconds < kGpsEpochFromUnixEpochS)
    throw bus::ConfigError(path.string() + ": start time " + std::to_string(seconds) +
                           " s since 1970 is before the GPS epoch");
  tag.start_gps_ns =
      (static_cast<std::int64_t>(seconds) - kGpsEpochFromUnixEpochS) * 1'000'000'000 +
      std::llround(fraction * 1e9);
  for (std::size_t at = kHeaderBytes + kStartBytes; at < bytes.size(); at += kRecordBytes) {
    const TimeTag::Record r{readLittleEndian<std::uint32_t>(bytes, at),
                            readLittleEndian<std::uint32_t>(bytes, at + 4)};
    if (!tag.records.empty() && r.tick_ms < tag.records.back().tick_ms)
      throw bus::ConfigError(path.string() + ": record " + std::to_string(tag.records.size()) +
                             " tick " + std::to_string(r.tick_ms) + " ms goes back in time");
    tag.records.push_back(r);
  }
  if (tag.records.empty()) throw bus::ConfigError(path.string() + ": no records");
  return tag;
}

}  // namespace navbus::importers
