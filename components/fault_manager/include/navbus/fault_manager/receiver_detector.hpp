// The cross-receiver detector of the fault pipeline (issue "redundant sensors"): the observation
// epochs of every configured GNSS receiver, aligned by their time, go through
// core::ReceiverClockMonitor (each receiver's clock against its own prediction) and
// core::ReceiverPairConsistency (the reference receiver's pseudoranges of the shared satellites
// against each other receiver's: a common-mode parity GLR). A clock jump is a decision
// (detector "receivers", SOURCE_RECEIVER_CLOCK) naming the receiver; a satellite whose
// pseudoranges differ between two receivers is a decision (SOURCE_SATELLITE) naming the
// satellite, ambiguous between the two receivers (both candidates), and the satellite leaves that
// pair's test and of every receiver's clock test. Each decision is followed by its command, at the
// data time just before the epoch that showed the fault: the receiver's clock compensated by the
// jump (CMD_COMPENSATE_BIAS, SOURCE_RECEIVER_CLOCK), or the satellite excluded (SCOPE_ALL: a
// spoofer forges both of its measurements). A filter that waits for this detector's judgement
// (fault_monitor.receivers_judged, FaultMonitorProgress.gnss_judged_up_to_gps_ns) fuses that
// epoch after the command, as offline.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <navbus_idl/Gnss.h>

#include "navbus/core/integrity/receiver_consistency.hpp"
#include "navbus/fault_manager/fault_config.hpp"
#include "navbus/fault_manager/fault_output.hpp"

namespace navbus::fault_manager {

class ReceiverDetector {
 public:
  /// FaultDecision.detector of its decisions.
  static constexpr const char* kDetectorName = "receivers";
  explicit ReceiverDetector(const ReceiverDetectorConfig& config);

  /// One receiver's epoch as received (any receiver, any order between them; in time order per
  /// receiver). Epochs of other receiver ids are counted and not used; satellites not valid or
  /// not finite are counted and left out.
  void onEpoch(const navbus::GnssObservationEpoch& msg, FaultOutput& out);
  /// A receiver's stream ended or was declared lost after its epoch at `last_time_ns` (0: the
  /// latest this detector has): times after it no longer wait for its epochs (the others' are
  /// tested as they come; a time with fewer than two receivers is settled untested). An epoch of
  /// it after that time makes it waited for again.
  void receiverGone(std::uint32_t id, std::int64_t last_time_ns, FaultOutput& out);

  struct Counters {
    std::uint64_t epochs{0}, other_receivers{0}, satellites_left_out{0};
    std::uint64_t late{0};          ///< older than the last time tested (or repeated)
    std::uint64_t tested{0};        ///< aligned epochs of all receivers tested
    std::uint64_t incomplete{0};    ///< times dropped: a receiver's epoch missing
    std::uint64_t without_gone{0};  ///< times tested without a receiver gone (ended or lost)
    std::uint64_t clock_jumps{0}, satellites{0};
    double max_clock_statistic{0.0}, max_satellite_statistic{0.0};
  };
  const Counters& counters() const { return counters_; }
  /// Data time up to which every receiver's epochs are tested (and commanded); -1: none yet.
  std::int64_t testedUpToNs() const { return last_tested_ns_; }
  std::string summary() const;

 private:
  using Epoch = std::vector<core::ReceiverSatellite>;
  struct Slot {
    std::vector<std::optional<Epoch>> receivers;
    std::size_t received{0};
  };
  int receiverOf(std::uint32_t id) const;
  /// Every receiver still waited for at `time_ns` has delivered its epoch of the slot.
  bool complete(std::int64_t time_ns, const Slot& slot) const;
  Epoch toCore(const navbus::GnssObservationEpoch& msg);
  void drain(FaultOutput& out);
  void test(std::int64_t time_ns, const Slot& slot, FaultOutput& out);
  void reportClock(std::int64_t time_ns, std::size_t r, const core::ClockJump& j, FaultOutput& out);
  void reportSatellite(std::int64_t time_ns, std::size_t r, const core::PairConsistencyResult& p,
                       FaultOutput& out);

  ReceiverDetectorConfig config_;
  std::vector<core::ReceiverClockMonitor> clocks_;    ///< per receiver
  std::vector<core::ReceiverPairConsistency> pairs_;  ///< per receiver after the reference
  std::vector<std::deque<std::int64_t>> pair_times_;  ///< per pair: its tested times (onsets)
  std::map<std::int64_t, Slot> pending_;              ///< by time, waiting for every receiver
  std::vector<int> decided_svs_;  ///< satellites decided: out of every receiver's clock test
  /// Per receiver: ended or lost after this time, not waited for beyond it (max: waited for).
  std::vector<std::int64_t> gone_after_ns_;
  std::vector<std::int64_t> latest_ns_;  ///< per receiver: its latest epoch's time
  Epoch scratch_;
  bool printed_detectable_{false};  ///< the first pair's minimum detectable difference, once
  std::int64_t last_tested_ns_{-1};
  Counters counters_;
};

}  // namespace navbus::fault_manager
