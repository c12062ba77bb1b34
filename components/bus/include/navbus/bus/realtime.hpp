// The real-time option of every participant: a `realtime:` block in its configuration (the same
// keys in every participant's file), off by default:
//
//   realtime: {policy: fifo, priority: 10, cpus: [1], lock_memory: true}
//
// applied to the process's main thread before the DDS participant is created, so that the
// threads Fast DDS creates (Fast DDS 2.9 has no per-thread settings) inherit the scheduling
// class, priority and CPU affinity (the threads that exist already are given them too). The main
// thread, which takes the samples and runs the pipeline, keeps the same priority as the DDS
// threads: under fifo and rr a thread is not preempted by one of equal priority, so a burst of
// receptions cannot interrupt the processing, and a woken processing thread does not preempt a
// receive thread that is still handing its sample over (one priority above them cost 20-40 us
// at the median of each hop, docs/results.md "Latency tail").
// Memory is locked as it is touched (mlockall with MCL_ONFAULT: locking every thread's whole stack
// would cost megabytes), and the main thread's stack is touched ahead. What the kernel granted is
// read back and reported; a refusal is a ConfigError naming the key, the value and the system's
// reason.
#pragma once

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace navbus::bus {

enum class SchedulingPolicy { kOther, kFifo, kRoundRobin };

struct RealtimeOptions {
  SchedulingPolicy policy{SchedulingPolicy::kOther};
  int priority{0};        ///< 1..99 for fifo and rr (Linux), 0 for other
  std::vector<int> cpus;  ///< core numbers; empty: as inherited
  bool lock_memory{false};
  bool requested() const {
    return policy != SchedulingPolicy::kOther || !cpus.empty() || lock_memory;
  }
};

/// The top-level key of the block.
inline constexpr const char* kRealtimeKey = "realtime";
/// The main thread's stack touched ahead under lock_memory [bytes].
inline constexpr std::size_t kPrefaultedStackBytes = 256 * 1024;

/// Reads the `realtime` block (absent: nothing requested); ConfigError names the key and value.
RealtimeOptions readRealtime(const YAML::Node& config);

/// What the kernel granted the calling thread, read back.
struct RealtimeGrant {
  SchedulingPolicy policy{SchedulingPolicy::kOther};
  int priority{0};
  std::vector<int> cpus;      ///< the thread's affinity
  bool memory_locked{false};  ///< read back: the process has locked memory (VmLck > 0)
  std::string text() const;
};

/// Applies the options to the calling thread (and so to the threads it creates) and the
/// process (memory); throws ConfigError naming the key, the value and the system's reason when
/// the kernel refuses (no CAP_SYS_NICE, a container without it, RLIMIT_MEMLOCK, a core this
/// process may not use). Nothing requested: nothing changed, the current state read back.
RealtimeGrant applyRealtime(const RealtimeOptions& options);

/// "other", "fifo", "rr".
const char* policyName(SchedulingPolicy policy);
/// A list of core numbers as the `cpus` key takes it: "[0, 1]".
std::string cpuListText(const std::vector<int>& cpus);

}  // namespace navbus::bus
