// Reclaims the shared memory that Fast DDS participants killed without a shutdown (kill -9, a
// crash) leave in /dev/shm. Fast DDS 2.9 removes its segments and ports on a clean shutdown
// only; a restarted participant opens new segments (random names) and never reclaims the old
// ones, so megabytes accumulate with every crash.
//
// Fast DDS marks what a live process uses with a file lock (src/cpp/utils/shared_memory/
// RobustExclusiveLock.hpp): every data segment `fastrtps_<16 hex>` has a lock file `..._el`
// its owner holds exclusively, every port `fastrtps_port<N>` a lock file `..._el` (exclusive)
// or `..._sl` (shared, held by each listener). A lock nobody holds is a dead owner's: this is
// the rule of Fast DDS's own `fastdds shm clean`, applied here from inside the participants.
// Data segments have random names and are never opened again once their owner is dead: they
// are removed when their lock file is free and at least `min_age` old (a new owner locks its
// file right after creating it). Ports are left alone by default: a port number is reused by
// the next participant that gets the same participant id, and a live process that still has
// the dead owner's port mapped would keep writing into the removed file, so that it could not
// reach the participant reusing the number (seen: discovery with a restarted participant never
// completed). Fast DDS re-initialises a zombie port itself when its number is reused. A port
// is 52 KiB plus a 32-byte mutex; `reclaim_ports` (for when no Fast DDS process is left on the
// host) removes them too, under the port's named mutex as Fast DDS does when it closes one.
// reclaimIfHostIdle() does that at a participant's clean exit when no lock in /dev/shm is held
// any more (no live shared-memory participant on the host): the last one out leaves nothing.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace navbus::bus {

struct ShmReclaimResult {
  std::uint64_t zombie_segments{0};
  std::uint64_t zombie_ports{0};
  std::uint64_t bytes_reclaimed{0};
  std::uint64_t segments_in_use{0};
  std::uint64_t ports_in_use{0};
  std::uint64_t zombie_ports_left{0};  ///< dead owners' ports not reclaimed (see above)
};

/// Removes the data segments (and with `reclaim_ports` the ports) of dead Fast DDS processes
/// from `dir` (Linux: /dev/shm).
ShmReclaimResult reclaimSharedMemory(const std::string& dir = "/dev/shm",
                                     std::chrono::milliseconds min_age = std::chrono::seconds(1),
                                     bool reclaim_ports = false);

/// True while a live process holds a Fast DDS lock in `dir` (a participant using shared memory).
bool sharedMemoryInUse(const std::string& dir = "/dev/shm");

/// When !sharedMemoryInUse(dir) (every participant that used shared memory is gone), removes
/// everything dead participants left, ports included; otherwise nothing. Returns what was
/// removed.
ShmReclaimResult reclaimIfHostIdle(const std::string& dir = "/dev/shm");

/// Bytes in `dir` of the data segments (or, with `ports`, the ports) whose owner is dead: 0
/// when nothing was left behind.
std::uint64_t zombieSharedMemoryBytes(const std::string& dir = "/dev/shm", bool ports = false);

}  // namespace navbus::bus
