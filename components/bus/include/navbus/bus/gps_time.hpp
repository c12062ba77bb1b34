// GPS time and Unix time: the one place for the GPS epoch and the leap seconds.
#pragma once

#include <cstdint>

namespace navbus::bus {

inline constexpr std::uint64_t kNsPerSecond = 1'000'000'000ULL;
/// The GPS epoch (1980-01-06 00:00:00 UTC) after the Unix epoch [ns].
inline constexpr std::uint64_t kGpsEpochAfterUnixNs = 315'964'800ULL * kNsPerSecond;
/// GPS time ahead of UTC: the leap seconds since 1980 [ns] (18 since 2017-01-01).
inline constexpr std::uint64_t kGpsAheadOfUtcNs = 18ULL * kNsPerSecond;

/// [ns, GPS time] -> [ns since the Unix epoch, UTC], with today's leap seconds.
constexpr std::uint64_t gpsToUnixNs(std::uint64_t gps_ns) {
  return gps_ns + kGpsEpochAfterUnixNs - kGpsAheadOfUtcNs;
}
/// [ns since the Unix epoch, UTC] -> [ns, GPS time].
constexpr std::uint64_t unixToGpsNs(std::uint64_t unix_ns) {
  return unix_ns - kGpsEpochAfterUnixNs + kGpsAheadOfUtcNs;
}

}  // namespace navbus::bus
