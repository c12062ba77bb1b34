// The parity detector of the fault pipeline (issue "redundant sensors"): the navigation-rate
// increments of every configured IMU unit, aligned by their time, go through
// core::ImuArrayParity (the parity space of all the units' gyros and of all their
// accelerometers, lever arms accounted for, the GLR of seed 000 on the parity residual). An
// isolation becomes a decision (detector "parity") naming the unit in `sensor_id` and its axis,
// and, when configured, CMD_FAIL_SENSOR_AXIS for that unit and axis; an ambiguous isolation
// (two instruments whose signatures cannot be told apart, e.g. the same axis of two parallel
// units) is a decision with both candidates and, when configured, CMD_SUSPECT_SENSOR_AXIS for
// each (the filter's lanes say which: nav_filter suspect_lanes.hpp). Either way the instruments
// decided leave the parity test, which goes on with the others while they have parity.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <navbus_idl/Fault.h>
#include <navbus_idl/Imu.h>
#include <navbus_idl/Navigation.h>

#include "navbus/bus/imu_alignment.hpp"
#include "navbus/bus/validation.hpp"
#include "navbus/core/integrity/imu_array_parity.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/fault_output.hpp"

namespace navbus::fault_manager {

class ParityDetector {
 public:
  /// Throws bus::ConfigError (naming the field) when the array cannot be monitored.
  explicit ParityDetector(const ParityDetectorConfig& config);

  /// One increment as received (any unit, any order between units; in time order per unit).
  /// Increments of other sensor ids, failing validation or at another interval are counted and
  /// not used.
  void onIncrement(const navbus::ImuIncrement& msg, FaultOutput& out);

  struct Counters {
    std::uint64_t increments{0}, other_sensors{0}, invalid{0}, wrong_interval{0};
    std::uint64_t late{0};        ///< older than the last time tested (or repeated)
    std::uint64_t samples{0};     ///< aligned samples of all units tested (or learning)
    std::uint64_t incomplete{0};  ///< times dropped: a unit's increment lost, or a unit silent
    std::uint64_t gaps{0};        ///< breaks in the aligned times: the tests restarted
    std::uint64_t detections{0}, ambiguous{0}, commands{0};
    std::uint64_t named_by_lanes{0};  ///< ambiguous decisions whose unit the lanes named
    std::uint64_t new_runs{0};        ///< the units' source restarted at an earlier time
    /// Increments before each unit's first one taken in a run, by its sequence numbers (which
    /// start at 1): the reader joined after the unit's stream began.
    std::uint64_t missed_at_start{0};
    std::array<double, core::kImuInstrumentKinds> max_statistic{};
  };
  const Counters& counters() const { return counters_; }
  /// A filter lane's solution (navbus/nav/lane_solution): once the lanes name the faulty one
  /// of an ambiguous decision's two candidates (named_faulty_for_decision), a decision
  /// (detector "lanes") names that unit, at that solution's time. Once per decision.
  void onLaneSolution(const navbus::LaneSolution& lane, FaultOutput& out);
  /// The unit's increments ended as announced; true once every unit's have.
  bool onUnitEnded(std::uint32_t sensor_id);
  /// Every time up to this one is tested, or dropped (-1: none yet).
  std::int64_t testedUpToNs() const { return aligner_.releasedNs(); }
  const core::ImuArrayParity& array() const { return *array_; }
  /// The largest statistic of the latest aligned sample, per kind (0 while learning).
  const core::ImuArrayParity::Result& latest() const { return latest_; }
  /// The minimum detectable biases, one line per kind (printed at start-up).
  std::string minimumDetectableBiases() const;
  std::string summary() const;

 private:
  /// Index of a sensor id among the units, or -1.
  int unitOf(std::uint32_t sensor_id) const;
  /// Tests the complete slots in time order; drops the oldest when a missing unit's increment
  /// is lost or too many times wait.
  void drain(FaultOutput& out);
  /// The array as configured, every instrument in it; throws bus::ConfigError (naming the
  /// field) when it cannot be monitored.
  void makeArray();
  /// The units' source started over at an earlier time (a restarted simulator or replay): the
  /// test starts over too, every instrument back in the array, nothing of the earlier run kept.
  void startNewRun();
  /// Counts (and says) the increments a unit sent before the first one taken in this run.
  void noteMissedStart(const navbus::ImuIncrement& first);
  void test(std::int64_t time_ns, const bus::ImuUnitAligner::Increments& units, FaultOutput& out);
  void report(std::int64_t time_ns, const core::ImuArrayDetection& d, FaultOutput& out);

  ParityDetectorConfig config_;
  std::optional<core::ImuArrayParity> array_;
  std::int64_t period_ns_;
  bus::ValidationLimits limits_;
  bus::ImuUnitAligner aligner_;      ///< the units' increments by time, waiting for every unit
  std::uint32_t ended_units_{0};     ///< bit per unit whose increments ended
  std::int64_t last_tested_ns_{-1};  ///< -1: the next time tested starts a new window
  std::array<std::uint64_t, core::ImuArrayParity::kMaxUnits> latest_seq_{};  ///< per unit
  core::ImuArrayParity::Result latest_;
  Counters counters_;
  /// Ambiguous decisions by id, until the lanes name one of their candidates (the latest few).
  std::map<std::uint32_t, navbus::FaultDecision> suspects_;
  static constexpr std::size_t kSuspectsKept = 16;
};

}  // namespace navbus::fault_manager
