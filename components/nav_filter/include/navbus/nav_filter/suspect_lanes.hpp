// Which of two suspect units failed, for the lanes (lane_set.hpp). A parity decision that cannot
// tell two units apart (the same axis of two parallel units) names both, in one
// CMD_SUSPECT_SENSOR_AXIS per candidate (after a CMD_RELEARN_BIAS for each, so that both lanes
// may learn the step). Each lane estimates its own unit's biases: from the two suspect lanes'
// estimates of that instrument at the last selected time before the onset, and at every
// selected time after it, core::LaneEvidenceTest names the unit whose estimate moved (or whose
// lane alone fails its consistency test), and its lane is left from that time. The selection calls
// it in time order, once per selected time, so the bus and offline leave the lane at the same time.
// Pure logic.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <navbus_idl/Navigation.h>

#include "navbus/core/integrity/lane_evidence.hpp"
#include "navbus/core/math/ring_buffer.hpp"
#include "navbus/nav_filter/filter_config.hpp"

namespace navbus::nav_filter {

class SuspectLanes {
 public:
  /// One candidate of a decision (a CMD_SUSPECT_SENSOR_AXIS for the unit of lane `lane`).
  struct Suspect {
    std::uint32_t decision_id{0};
    int lane{-1};
    bool accelerometer{false};
    int axis{0};               ///< the unit's axis
    std::int64_t onset_ns{0};  ///< the fault's onset [ns, GPS time]
  };
  /// A unit the lanes' evidence named: its lane is left from time_ns.
  struct Named {
    Suspect suspect;
    std::int64_t time_ns{0};
    core::LaneEvidenceDecision evidence;
  };

  SuspectLanes(const std::vector<LaneUnit>& units, const core::LaneEvidenceConfig& config);

  /// A candidate; the comparison opens when the decision's second candidate arrives (a later
  /// decision's pair replaces an open one, counted). Returns what the command's answer says.
  std::string onSuspect(const Suspect& s);
  /// Every lane's solution at a selected time, in lane order (nullptr: none at this time), in
  /// time order: the unit named at this time, if any.
  std::optional<Named> atSelection(std::int64_t time_ns,
                                   const std::vector<const navbus::NavigationSolution*>& at);
  /// The new run of the lanes' source: nothing of the earlier one is kept.
  void newRun();

  struct Counters {
    std::uint64_t questions{0};  ///< pairs compared
    std::uint64_t named{0};
    std::uint64_t expired{0};     ///< gave up after max_wait_s
    std::uint64_t superseded{0};  ///< replaced by a later decision's pair before deciding
    std::uint64_t unpaired{0};    ///< selected times after the onset without both lanes
    std::uint64_t old_onset{0};   ///< onsets before the history kept: its oldest time used
  };
  const Counters& counters() const { return counters_; }
  std::string summary() const;

 private:
  /// Bias estimates and 1-sigmas of a lane's unit at one time [unit axes: gyros then
  /// accelerometers, rad/s and m/s^2].
  struct Estimates {
    std::int64_t time_ns{0};
    std::array<core::LaneBiasEstimate, 6> instruments{};
  };
  struct Question {
    std::array<Suspect, 2> suspects;
    /// Both lanes' estimates at the last selected time before the onset (a lane that re-learns
    /// the bias from the onset has its variance grown at the onset).
    std::optional<std::array<core::LaneBiasEstimate, 2>> reference;
    bool testing{false};  ///< the test is open (a time after the onset was selected)
  };
  /// Selected times kept per lane, for a reference before an onset the selection has passed.
  static constexpr std::size_t kHistory = 256;
  /// A lane's kept times: a ring of fixed size (a deque allocated a block every 3 selections).
  using History = core::RingBuffer<Estimates>;

  Estimates inUnitAxes(std::size_t lane, const navbus::NavigationSolution& s) const;
  static core::LaneBiasEstimate instrument(const Estimates& e, const Suspect& s);
  /// The latest kept estimates of both suspect lanes at one time before the onset.
  std::optional<std::array<core::LaneBiasEstimate, 2>> referenceFromHistory(const Question& q);

  std::vector<LaneUnit> units_;
  core::LaneEvidenceTest test_;
  std::vector<History> history_;  ///< per lane, at selected times
  std::optional<Suspect> first_;  ///< a decision's first candidate, waiting for its second
  std::optional<Question> question_;
  std::vector<Named> named_;
  Counters counters_;
};

}  // namespace navbus::nav_filter
