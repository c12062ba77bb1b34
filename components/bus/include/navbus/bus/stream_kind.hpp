// Which sensor stream: the key of the stream table (streams.hpp), alone for pure logic that
// needs no more of it (the stream watchdog).
#pragma once

#include <cstdint>

namespace navbus::bus {

/// A sensor stream: what one kind of sensor produces, whichever topic carries it.
enum class StreamKind : std::uint8_t { kImu, kImuRaw, kGnssObservations, kGnssFix, kStarTracker };

}  // namespace navbus::bus
