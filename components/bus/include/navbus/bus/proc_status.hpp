// One "kB" field of a process's /proc/PID/status (VmHWM, VmRSS, VmLck, ...): how the kernel
// accounts a process's memory, read where navbus reports it (the real-time option's locked
// memory, navbus-filter's peak resident memory in `navbus latency table`).
#pragma once

#include <string>

namespace navbus::bus {

/// The field `name` (without the colon) of /proc/`process`/status [kB]; `process` is a pid or
/// "self". -1 when the process or the field does not exist.
long procStatusKilobytes(const std::string& process, const std::string& name);

}  // namespace navbus::bus
