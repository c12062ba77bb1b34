#include "navbus/bus/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

#include "navbus/bus/config.hpp"
#include "navbus/bus/key_reader.hpp"
#include "navbus/bus/proc_status.hpp"

namespace navbus::bus {

namespace {

int linuxPolicy(SchedulingPolicy p) {
  switch (p) {
    case SchedulingPolicy::kFifo:
      return SCHED_FIFO;
    case SchedulingPolicy::kRoundRobin:
      return SCHED_RR;
    case SchedulingPolicy::kOther:
      return SCHED_OTHER;
  }
  return SCHED_OTHER;
}

SchedulingPolicy fromLinux(int policy) {
  if (policy == SCHED_FIFO) return SchedulingPolicy::kFifo;
  if (policy == SCHED_RR) return SchedulingPolicy::kRoundRobin;
  return SchedulingPolicy::kOther;
}

std::string systemReason(int error) {
  std::string reason = std::strerror(error);
  if (error == EPERM) reason += " (needs CAP_SYS_NICE: run as root, or add it to the container)";
  return reason;
}

void checkOptions(const RealtimeOptions& o) {
  const bool realtime_class = o.policy != SchedulingPolicy::kOther;
  if (realtime_class) {
    const int lo = sched_get_priority_min(linuxPolicy(o.policy));
    const int hi = sched_get_priority_max(linuxPolicy(o.policy));
    if (o.priority < lo || o.priority > hi) {
      throw ConfigError("configuration realtime.priority = " + std::to_string(o.priority) +
                        " is outside " + std::to_string(lo) + ".." + std::to_string(hi) +
                        " for policy " + policyName(o.policy));
    }
  } else if (o.priority != 0) {
    throw ConfigError("configuration realtime.priority = " + std::to_string(o.priority) +
                      " needs policy fifo or rr (policy other has priority 0)");
  }
  for (const int cpu : o.cpus) {
    if (cpu < 0 || cpu >= CPU_SETSIZE) {
      throw ConfigError("configuration realtime.cpus: " + std::to_string(cpu) +
                        " is not a core number");
    }
  }
}

void setAffinity(const std::vector<int>& cpus) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int cpu : cpus) CPU_SET(cpu, &set);
  const int error = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
  if (error != 0) {
    throw ConfigError("configuration realtime.cpus = " + cpuListText(cpus) +
                      " refused: " + std::strerror(error) + " (this machine has " +
                      std::to_string(sysconf(_SC_NPROCESSORS_ONLN)) +
                      " online cores, numbered from 0; a container may allow fewer)");
  }
}

/// The process's other threads (those that exist already: a signal watcher, a logger), which
/// would not inherit what this thread is given.
std::vector<pid_t> otherThreads() {
  std::vector<pid_t> tids;
  const pid_t self = static_cast<pid_t>(syscall(SYS_gettid));
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    const pid_t tid = static_cast<pid_t>(std::stol(entry.path().filename().string()));
    if (tid != self) tids.push_back(tid);
  }
  return tids;
}

/// Gives the other threads this thread's affinity, class and priority.
void applyToOtherThreads(const RealtimeOptions& o) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int cpu : o.cpus) CPU_SET(cpu, &set);
  sched_param param{};
  param.sched_priority = o.priority;
  for (const pid_t tid : otherThreads()) {
    // A thread that ended meanwhile (ESRCH) needs nothing; any other refusal was already met
    // by this thread's own call.
    if (!o.cpus.empty()) sched_setaffinity(tid, sizeof(set), &set);
    if (o.policy != SchedulingPolicy::kOther) {
      sched_setscheduler(tid, linuxPolicy(o.policy), &param);
    }
  }
}

void setScheduling(SchedulingPolicy policy, int priority, const char* key) {
  sched_param param{};
  param.sched_priority = priority;
  const int error = pthread_setschedparam(pthread_self(), linuxPolicy(policy), &param);
  if (error != 0) {
    throw ConfigError(std::string("configuration ") + key + " = " + policyName(policy) +
                      " (priority " + std::to_string(priority) +
                      ") refused: " + systemReason(error));
  }
}

/// Touches the next `bytes` of this thread's stack, so that its pages are there (and locked).
void prefaultStack() {
  volatile unsigned char stack[kPrefaultedStackBytes];
  for (std::size_t i = 0; i < sizeof(stack); i += 4096) stack[i] = 0;
}

void lockMemory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE | MCL_ONFAULT) != 0) {
    const int error = errno;
    throw ConfigError(
        "configuration realtime.lock_memory = true refused: " + std::string(std::strerror(error)) +
        (error == ENOMEM || error == EPERM
             ? " (the locked-memory limit, ulimit -l, is too small: raise it, e.g. compose "
               "`ulimits: {memlock: -1}`, or grant CAP_IPC_LOCK)"
             : ""));
  }
  prefaultStack();
}

}  // namespace

std::string cpuListText(const std::vector<int>& cpus) {
  std::string text = "[";
  for (std::size_t i = 0; i < cpus.size(); ++i) {
    text += (i ? ", " : "") + std::to_string(cpus[i]);
  }
  return text + "]";
}

const char* policyName(SchedulingPolicy policy) {
  switch (policy) {
    case SchedulingPolicy::kFifo:
      return "fifo";
    case SchedulingPolicy::kRoundRobin:
      return "rr";
    case SchedulingPolicy::kOther:
      return "other";
  }
  return "other";
}

RealtimeOptions readRealtime(const YAML::Node& config) {
  RealtimeOptions o;
  KeyReader r(config[kRealtimeKey], kRealtimeKey);
  r.choice("policy", o.policy,
           {{"other", SchedulingPolicy::kOther},
            {"fifo", SchedulingPolicy::kFifo},
            {"rr", SchedulingPolicy::kRoundRobin}});
  r.integer("priority", o.priority, {0, 99});
  r.value("cpus", o.cpus);
  r.value("lock_memory", o.lock_memory);
  r.finish();
  checkOptions(o);
  return o;
}

RealtimeGrant applyRealtime(const RealtimeOptions& o) {
  checkOptions(o);
  if (!o.cpus.empty()) setAffinity(o.cpus);
  if (o.policy != SchedulingPolicy::kOther) setScheduling(o.policy, o.priority, "realtime.policy");
  if (o.policy != SchedulingPolicy::kOther || !o.cpus.empty()) applyToOtherThreads(o);
  if (o.lock_memory) lockMemory();
  RealtimeGrant g;
  int policy = SCHED_OTHER;
  sched_param param{};
  if (pthread_getschedparam(pthread_self(), &policy, &param) == 0) {
    g.policy = fromLinux(policy);
    g.priority = param.sched_priority;
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  if (pthread_getaffinity_np(pthread_self(), sizeof(set), &set) == 0) {
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
      if (CPU_ISSET(cpu, &set)) g.cpus.push_back(cpu);
    }
  }
  // Read back: a build with AddressSanitizer ignores mlockall (it succeeds and locks nothing).
  g.memory_locked = o.lock_memory && procStatusKilobytes("self", "VmLck") > 0;
  return g;
}

std::string RealtimeGrant::text() const {
  return std::string("policy ") + policyName(policy) + " priority " + std::to_string(priority) +
         ", cpus " + cpuListText(cpus) + ", memory " + (memory_locked ? "locked" : "not locked");
}

}  // namespace navbus::bus
