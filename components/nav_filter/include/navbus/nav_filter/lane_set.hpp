// navbus-filter's lanes (redundant IMUs, filter `lanes:`): one FilterPipeline per IMU unit, each
// with that unit's increments turned into body axes (its mounting) and the antenna seen from the
// unit's place (its lever arm), every lane fed every aiding measurement and command; the
// published solution is the selected lane's (core::LaneSelector: the best innovation fit with
// hysteresis, an unavailable lane left at once), moved to the body origin, naming its lane, with
// the reset deltas and counter of the latest switch. Every lane's solution at every time also
// goes out on its own (LaneSolution). A filter without `lanes:` is one lane: its solutions pass
// through unchanged but for lane_id.
//
// Lanes run on the same inputs in the same order, each from its own IMU, so they reach a data
// time in turn; the selection at a time waits until every lane has passed it (a lane silent for
// sequencer_max_wait_s of running time, or max_pending solutions behind, is unavailable there,
// counted), so the bus and offline select the same. What belongs to the filter as a whole stays
// with lane 0 (the filter's own IMU, inputs.imu): the participant's health counters, the
// diagnostics the fault manager's GLR reads, the answers to commands and the fault monitor's watch.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <navbus_idl/Navigation.h>

#include "navbus/core/filter/lane_selector.hpp"
#include "navbus/nav_filter/combined_imu.hpp"
#include "navbus/nav_filter/filter_pipeline.hpp"
#include "navbus/nav_filter/judgement_tracker.hpp"
#include "navbus/nav_filter/suspect_lanes.hpp"

namespace navbus::nav_filter {

class LaneSet {
 public:
  struct Sinks {
    FilterPipeline::Sinks filter;  ///< the published solution and what lane 0 answers for
    std::function<void(const navbus::LaneSolution&)> lane{};  ///< every lane's; may be empty
  };

  LaneSet(const FilterConfig& config, bus::HealthCounters& health, Sinks sinks);

  // The inputs of FilterPipeline, given to the lanes they concern.
  void onImu(const navbus::ImuIncrement& msg);
  void onImuBlock(const navbus::ImuIncrementBlock& msg);
  void onGnssObservations(const navbus::GnssObservationEpoch& msg);
  void onGnssFix(const navbus::GnssFix& msg);
  void onStarTracker(const navbus::StarTrackerAttitude& msg);
  void onGnssObservationsBlock(const navbus::GnssObservationEpochBlock& msg);
  void onGnssFixBlock(const navbus::GnssFixBlock& msg);
  void onStarTrackerBlock(const navbus::StarTrackerAttitudeBlock& msg);
  void onStreamEnded(bus::StreamKind kind, std::uint32_t id);
  void onDecision(const navbus::FaultDecision& d) { lanes_.front()->onDecision(d); }
  /// An IMU-axis or IMU-stream command naming a unit goes to that unit's lane (failing an axis
  /// takes the lane out of the selection from the command's data time); every other command to
  /// every lane (lane 0 answers).
  void onCommand(const navbus::FilterCommand& c,
                 const std::optional<std::string>& writer_identity = std::nullopt);
  void pump(std::int64_t now_ns);
  void resumedAfterStall(std::int64_t now_ns, std::int64_t stalled_ns);
  void setWritersAlive(bus::StreamKind kind, bool alive, std::int64_t now_ns);
  void flush(std::int64_t now_ns);
  void publishHeldSolution();
  /// Lane 0 follows the diagnostics' judgement; the selection follows the parity test's
  /// (imu_judged_up_to_gps_ns): once a fault manager reports it, a time is selected only when it
  /// is judged and the commands the report names are in (or judgement_wait_ns of running time
  /// has passed: counted), so that a unit failed at a time is left at that time on the bus as
  /// offline.
  void onFaultMonitorProgress(const navbus::FaultMonitorProgress& report);
  void setFaultMonitorAlive(bool alive);
  bool degraded() const { return lanes_[static_cast<std::size_t>(selectedIndex())]->degraded(); }
  std::uint64_t newRuns() const { return lanes_.front()->newRuns(); }

  int lanes() const { return static_cast<int>(lanes_.size()); }
  /// The selected lane's engine (lane 0 before any selection).
  const core::NavigationEngine& engine() const {
    return lanes_[static_cast<std::size_t>(selectedIndex())]->engine();
  }
  const FilterPipeline& lane(int k) const { return *lanes_[static_cast<std::size_t>(k)]; }
  /// The lane whose solutions are published (0 before any selection; config lanes.units order).
  int selectedLane() const { return selectedIndex(); }
  const core::LaneSelection& selection() const { return selector_.last(); }
  /// Each lane's unit (lanes.units order; the least-squares lane last: body axes, body origin).
  const LaneUnit& laneUnit(int k) const { return lane_units_[static_cast<std::size_t>(k)]; }
  /// The least-squares lane's combination (lanes.least_squares), or null.
  const CombinedImu* combined() const { return combined_ ? &*combined_ : nullptr; }
  std::string summary() const;

 private:
  struct Pending {
    navbus::NavigationSolution solution;  ///< at the body origin
    double test_ratio{0.0};
  };
  int selectedIndex() const { return selector_.last().lane < 0 ? 0 : selector_.last().lane; }
  int laneOf(std::uint32_t sensor_id) const;
  /// The lane on the least-squares combination, after the units' lanes.
  void addLeastSquaresLane();
  /// Gives that lane the combined increments released (at most to the parity test's judgement;
  /// `all`: everything, the data ended), with its re-learns where the combination changed.
  void feedCombined(bool all);
  navbus::FilterCommand relearnCommand(core::ImuInstrument kind, int axis, std::int64_t time_ns);
  template <class Fn>
  void forEach(Fn&& fn) {
    for (auto& lane : lanes_) fn(*lane);
  }
  void onLaneSolution(int k, const navbus::NavigationSolution& s);
  /// CMD_SUSPECT_SENSOR_AXIS: answered here (lane 0's gate), compared at the selections.
  void onSuspect(const navbus::FilterCommand& c, const std::optional<std::string>& writer_identity);
  /// The lanes' evidence at `time_ns` (the lanes' solutions `at`): a suspect unit named is left
  /// from that time.
  void judgeSuspects(std::int64_t time_ns, const std::vector<const Pending*>& at);
  /// The IMUs restarted at an earlier time (a lane began its new run `run`): what the earlier
  /// run holds goes out, and the selection starts over as a single filter does (sequence
  /// numbers from 1, the best lane taken without a reset counted, no exclusion, no judgement).
  void startNewRun(std::uint64_t run);
  /// Selects at every time all lanes have passed, oldest first; `all` releases what is held.
  void release(bool all);
  void select(std::int64_t time_ns);
  /// Lane k's own solution on the lanes topic (selected: the one published at its time).
  void publishLane(std::size_t k, const Pending& p, bool selected) const;
  bool available(int k, const Pending* p) const;
  /// Whether the selection at `time_ns` waits for the parity test's judgement.
  bool holdForParity(std::int64_t time_ns);
  /// A lane not failed by `time_ns` has no solution pending: the selection waits for it.
  bool missing(std::int64_t time_ns) const;
  /// Such a lane has been silent beyond the waits (it is passed over).
  bool anySilentLaneMissing(std::int64_t time_ns) const;

  FilterConfig config_;
  Sinks sinks_;
  std::vector<std::unique_ptr<bus::HealthCounters>>
      lane_health_;  ///< lanes 1..: what every lane is fed, counted once (by lane 0)
  std::vector<std::unique_ptr<FilterPipeline>> lanes_;
  std::vector<LaneUnit> lane_units_;  ///< each lane's IMU (the least-squares lane: its own id)
  std::optional<CombinedImu> combined_;
  std::uint64_t own_commands_{0};  ///< the least-squares lane's re-learns
  bool feeding_{false};            ///< within feedCombined()
  /// Running time the combination began to hold a complete time for the judgement (-1: none).
  std::int64_t combined_held_since_ns_{-1};
  std::uint64_t combined_unjudged_{0};  ///< times it went on without the judgement
  std::vector<std::deque<Pending>> pending_;
  std::vector<bool> excluded_;  ///< the lane's IMU axis was failed by a command
  /// ... from this data time on (the command's): unavailable at the times since
  std::vector<std::int64_t> excluded_from_ns_;
  /// The decision whose suspects the lanes' comparison found this lane's unit faulty (0: none).
  std::vector<std::uint32_t> named_for_decision_;
  JudgementTracker parity_judgements_;  ///< the parity test's progress, with its commands
  bool parity_reported_{false};
  std::int64_t parity_judged_ns_{-1};
  std::int64_t now_ns_{0};          ///< running time of the latest pump
  std::int64_t held_since_ns_{-1};  ///< running time the selection began to wait for it
  std::uint64_t parity_waits_timed_out_{0};
  /// Commands given to one lane (issuer, run, id): that lane answers them.
  std::set<std::tuple<std::string, std::uint64_t, std::uint64_t>> routed_;
  core::LaneSelector selector_;
  SuspectLanes suspects_;
  std::vector<const navbus::NavigationSolution*> suspect_view_;  ///< reused at each selection
  std::vector<core::LaneStatus> statuses_;
  std::vector<const Pending*> at_;  ///< each lane's solution at the time being selected
  core::LaneResetDelta last_delta_;
  /// Every lane's solution at the previous selected time (the reset deltas' reference).
  std::vector<std::optional<core::NavState>> previous_;
  std::uint64_t seq_{0};
  std::uint64_t passed_over_{0};  ///< times selected while a lane was not there yet
  std::uint64_t late_{0};  ///< lane solutions of times already selected (on the lanes topic only)
  std::int64_t last_selected_ns_{-1};
  std::uint64_t run_{0};  ///< the lanes' run being selected (FilterPipeline::newRuns())
  std::uint64_t solutions_earlier_runs_{0};
  std::vector<std::int64_t> heard_ns_;  ///< per lane: running time of its latest solution
  bool any_heard_{false};               ///< a lane has published a solution
};

}  // namespace navbus::nav_filter
