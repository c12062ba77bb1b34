// The increments of the filter's least-squares lane (`lanes.least_squares`): every unit's
// increments, aligned by time (bus::ImuUnitAligner), combined into one body-axis increment at
// the body origin (core::ImuArrayCombination, eq. 1), which that lane integrates as its IMU
// (its own sensor id, sequence numbers from 1). Pure logic.
//
// What the fault manager decides about an instrument acts on the combination at the decision's
// data time: a failed axis (CMD_FAIL_SENSOR_AXIS) and each suspect of an ambiguous decision
// (CMD_SUSPECT_SENSOR_AXIS) leave it from that time, and the lane re-learns the bias of that kind
// there (the combination's bias changed with its weights). An instrument whose loss would leave
// fewer than three spanning axes cannot leave: the combination is then unusable from that time
// (its lane is out of the selection). A unit whose stream ended leaves whole at its first time
// missing. The caller releases a time only once the fault manager has judged it (so that every
// command about it is in), as the lanes' selection waits: the combination is the same on the bus
// as offline.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <navbus_idl/Imu.h>

#include "navbus/bus/imu_alignment.hpp"
#include "navbus/bus/validation.hpp"
#include "navbus/core/ins/imu_array_combination.hpp"
#include "navbus/nav_filter/filter_config.hpp"

namespace navbus::nav_filter {

class CombinedImu {
 public:
  /// Throws bus::ConfigError naming lanes.least_squares when the units cannot be combined.
  explicit CombinedImu(const FilterConfig& config);

  /// The least-squares lane's configuration: its IMU is the combination (lane id, body axes,
  /// body origin), its white noise and bias random walks those of eq. 1's covariance with the
  /// worst single instrument out (so that it stays honest after one exclusion).
  const FilterConfig& laneConfig() const { return lane_config_; }

  /// Unit u's increment as received (lanes.units order).
  void onIncrement(int unit, const navbus::ImuIncrement& msg);
  /// The instrument leaves the combination from `from_ns` (a failed axis, a suspect).
  void exclude(core::ImuInstrument kind, int unit, int axis, std::int64_t from_ns);
  /// Unit u's increments ended as announced.
  void unitEnded(int unit) { aligner_.endUnit(unit); }

  struct Output {
    navbus::ImuIncrement increment;  ///< the lane's next increment
    /// The combination changed before this increment: the lane re-learns these biases here.
    std::array<bool, core::kImuInstrumentKinds> relearn{};
    /// An instrument had to leave but could not: from this increment on, unusable.
    bool unusable{false};
  };
  /// The next combined increment, once its time is complete (or will not be) and at or before
  /// `judged_ns`; `all`: whatever still waits (the data ended).
  std::optional<Output> next(std::int64_t judged_ns, bool all = false);
  /// A time waits beyond `judged_ns` (for the judgement, not for a unit).
  bool heldBeyond(std::int64_t judged_ns) const {
    const std::int64_t t = aligner_.oldestNs();
    return t >= 0 && t > judged_ns;
  }

  struct Counters {
    std::uint64_t increments{0};  ///< units' increments taken
    std::uint64_t invalid{0}, wrong_interval{0}, late{0};
    std::uint64_t combined{0};
    std::uint64_t incomplete{0};    ///< times combined without a unit's lost increment
    std::uint64_t not_spanning{0};  ///< times the units present did not span: not combined
    std::uint64_t excluded{0};      ///< instruments taken out
    std::uint64_t new_runs{0};
  };
  const Counters& counters() const { return counters_; }
  /// The combination the increment at `time_ns` of this run was made with (the data time of
  /// each change is kept: the selection, behind the combination, is scored with its own).
  const core::ImuArrayCombination& combinationAt(std::int64_t time_ns) const;
  std::string summary() const;

 private:
  struct Exclusion {
    core::ImuInstrument kind;
    int unit;
    int axis;  ///< -1: the whole unit
    std::int64_t from_ns;
  };
  void makeCombination();
  void startNewRun();
  /// Applies the exclusions due at `time_ns`; fills `out`'s relearn and unusable.
  void applyExclusions(std::int64_t time_ns, Output& out);

  std::vector<core::ImuArrayUnit> units_;
  std::uint32_t lane_id_;
  std::int64_t period_ns_;
  FilterConfig lane_config_;
  std::optional<core::ImuArrayCombination> combination_;
  /// Each change of this run: from that data time on, the combination as it became.
  std::vector<std::pair<std::int64_t, core::ImuArrayCombination>> changes_;
  std::optional<core::ImuArrayCombination> initial_;  ///< as configured
  bus::ImuUnitAligner aligner_;
  bus::ValidationLimits limits_;
  std::vector<Exclusion> exclusions_;  ///< waiting for their time, in arrival order
  std::array<std::uint64_t, bus::ImuUnitAligner::kMaxUnits> latest_seq_{};
  std::uint32_t ended_left_{0};  ///< bit per ended unit already taken out
  std::uint64_t seq_{0};
  bool usable_{true};
  Counters counters_;
};

}  // namespace navbus::nav_filter
