// A fault loop that cannot storm (issue: deterministic under load). The GLR detector asks this
// guard before it decides: a fault source (an IMU sensor axis, a satellite) decided
// `escalate_after` times within `window_s` of data time was not cured by what was commanded
// (re-learned or compensated biases, an exclusion later readmitted), so the next detection
// naming it escalates once (the GLR detector commands what is left: fail the axis, keep the
// satellite excluded), and later detections naming an escalated source are not decided again
// (counted). Pure logic: the caller supplies data times.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <set>
#include <tuple>
#include <vector>

namespace navbus::fault_manager {

struct RepeatGuardConfig {
  double window_s{300.0};  ///< [s] data time within which decisions on one source count
  int escalate_after{2};   ///< decisions on a source before the next one escalates
};

/// A fault source as a decision names it (FaultDecision source, sv_id, axis).
struct FaultSourceKey {
  int source{0};
  int sv_id{0};
  int axis{0};
  bool operator<(const FaultSourceKey& o) const {
    return std::tie(source, sv_id, axis) < std::tie(o.source, o.sv_id, o.axis);
  }
};

class RepeatGuard {
 public:
  enum class Verdict {
    kDecide,    ///< as configured
    kEscalate,  ///< decided often enough: what is left
    kSuppress,  ///< a source already escalated: not decided again
  };
  explicit RepeatGuard(const RepeatGuardConfig& config) : config_(config) {}

  /// A detection at `time_ns` naming `sources` (the isolated one first).
  Verdict onDetection(std::int64_t time_ns, const std::vector<FaultSourceKey>& sources);

  std::uint64_t escalations() const { return escalations_; }
  std::uint64_t suppressed() const { return suppressed_; }

 private:
  /// Decisions on `key` within the window before `time_ns` (older ones forgotten).
  int recentDecisions(const FaultSourceKey& key, std::int64_t time_ns);

  RepeatGuardConfig config_;
  std::map<FaultSourceKey, std::deque<std::int64_t>> decided_ns_;
  std::set<FaultSourceKey> escalated_;
  std::uint64_t escalations_{0};
  std::uint64_t suppressed_{0};
};

}  // namespace navbus::fault_manager
