// Input validation at the participant boundary: finite values, physical ranges, per-sensor
// monotonic time, duplicates and sequence gaps. Every rejection names the field and value.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <navbus_idl/Gnss.h>
#include <navbus_idl/Imu.h>
#include <navbus_idl/Navigation.h>
#include <navbus_idl/StarTracker.h>

namespace navbus::bus {

struct Rejection {
  navbus::RejectReason reason;
  std::string field;  ///< e.g. "delta_vel_b_mps[2]" or "satellites[3].sv_id"
  double value;       ///< the offending value (NaN shown as nan)
  std::string describe() const;
};

/// Physical limits; defaults cover aircraft, land vehicles and LEO spacecraft.
struct ValidationLimits {
  double max_specific_force_mps2{50.0 * 9.80665};  ///< accelerometer range
  double max_angular_rate_radps{35.0};             ///< ~2000 deg/s, above any RLG dither peak
  std::uint32_t max_interval_ns{1'000'000'000};    ///< longest IMU integration interval
  double min_pseudorange_m{1.0e7};
  double max_pseudorange_m{6.0e7};
  double max_pseudorange_rate_mps{2.0e4};  ///< LEO receiver plus satellite motion
  double min_sat_radius_m{2.0e7};          ///< GNSS orbit radius bounds
  double max_sat_radius_m{3.0e7};
  double max_height_m{5.0e6};  ///< receiver height bound (LEO included)
  double min_height_m{-1.0e3};
  double quaternion_norm_tolerance{1e-6};
  double max_star_tracker_sigma_rad{0.1};
  /// Plausible 1-sigma of a pseudorange and its rate: a receiver claiming less than a
  /// centimetre (a millimetre per second) or more than a kilometre (100 m/s) is not believed.
  double min_pseudorange_sigma_m{0.01};
  double max_pseudorange_sigma_m{1.0e3};
  double min_pseudorange_rate_sigma_mps{1.0e-3};
  double max_pseudorange_rate_sigma_mps{100.0};
};

std::optional<Rejection> validate(const navbus::ImuIncrement& s, const ValidationLimits& l);
/// The block's structure only: at least one increment, each of the block's sensor. Each
/// increment is then validated (and counted) as an ImuIncrement sample.
std::optional<Rejection> validate(const navbus::ImuIncrementBlock& s, const ValidationLimits& l);
std::optional<Rejection> validate(const navbus::ImuRawBlock& s, const ValidationLimits& l);
/// A measurement block's structure only (bus/streams.hpp SensorBlock): at least one element,
/// each of the block's sensor. Each element is then validated (and counted) as a sample of its
/// own topic.
std::optional<Rejection> validate(const navbus::GnssObservationEpochBlock& s,
                                  const ValidationLimits& l);
std::optional<Rejection> validate(const navbus::GnssFixBlock& s, const ValidationLimits& l);
std::optional<Rejection> validate(const navbus::StarTrackerAttitudeBlock& s,
                                  const ValidationLimits& l);
/// Epoch-level checks only (none today beyond the IDL bounds): a bad satellite costs that
/// satellite, not the epoch; see screenSatellites.
std::optional<Rejection> validate(const navbus::GnssObservationEpoch& s, const ValidationLimits& l);

/// A satellite of an epoch that cannot be used, and why.
struct SatelliteRejection {
  std::size_t index;  ///< in satellites()
  Rejection rejection;
};
/// Per-satellite checks: id 1..32, finite values, physical ranges, plausible sigmas, and an id
/// that appears more than once (every copy: which one is right cannot be told). The others
/// stay usable. No allocation when every satellite passes.
std::vector<SatelliteRejection> screenSatellites(const navbus::GnssObservationEpoch& s,
                                                 const ValidationLimits& l);
std::optional<Rejection> validate(const navbus::GnssFix& s, const ValidationLimits& l);
std::optional<Rejection> validate(const navbus::StarTrackerAttitude& s, const ValidationLimits& l);
/// Sizes consistent with n and m, finite values, satellite ids 1..32 on ranging rows,
/// positive innovation variances.
std::optional<Rejection> validate(const navbus::FilterDiagnostics& s, const ValidationLimits& l);

/// The latest data time accepted on any input of a participant [ns]: the reference a
/// sample's time is judged against (0: nothing accepted yet).
struct TimeReference {
  std::uint64_t latest_ns{0};
};

/// Rules for a sample far ahead of the data seen so far.
struct TimeJumpRule {
  /// Later than max(the stream's latest, the participant's latest) by more than this: rejected
  /// (REJECT_TIME_JUMP) and not adopted as the stream's time; 0: no check.
  std::uint64_t tolerance_ns{0};
  /// ... unless this many samples in a row continue from it (sequence and time increasing,
  /// each within the tolerance of the previous): a real resumption after a long silence, or a
  /// stream whose start arrived before the other streams' data that leads up to it. The last
  /// of them is accepted; the ones before were refused as candidates, and a caller that held
  /// them may use them then (Outcome::jump_held), so the outcome does not depend on the order
  /// in which the streams' samples arrived.
  /// The same count confirms a source restart: a sample whose time and sequence number are
  /// both behind the stream's latest is rejected as not monotonic, unless this many samples
  /// in a row continue from it (a restarted writer replaying its scenario from the start).
  int confirmations{3};
};

/// Tracks time and sequence per sensor id of one stream.
class SequenceTracker {
 public:
  struct Outcome {
    std::optional<Rejection> rejection;
    std::uint64_t missing{0};  ///< samples skipped according to the sequence number
    /// Of `missing`: samples numbered before the first one this tracker saw of the sensor
    /// (sequence counters start at 1): the reader joined late or missed the start.
    std::uint64_t missing_before_first{0};
    bool restarted{false};     ///< sequence went back while time went forward (writer restart)
    bool jump_adopted{false};  ///< a forward jump confirmed by the samples after it
    /// With jump_adopted: how many samples before this one, refused as REJECT_TIME_JUMP when
    /// they came, belong to the confirmed chain (they continue to this one).
    int jump_held{0};
    /// With a REJECT_TIME_JUMP rejection: this sample's place in a chain that may still be
    /// confirmed (1: it starts a new chain, and earlier candidates of the sensor are void).
    int jump_candidate{0};
    /// Time and sequence went back, confirmed by the samples after it: the source started a
    /// new run, and the stream continues from this sample.
    bool source_restarted{false};
  };
  SequenceTracker() = default;
  /// `reference` (optional, outliving the tracker) is shared by the participant's streams.
  SequenceTracker(TimeJumpRule rule, TimeReference* reference)
      : rule_(rule), reference_(reference) {}
  /// Checks a sample and, if accepted, records it.
  Outcome check(std::uint32_t sensor_id, std::uint64_t seq, std::uint64_t time_ns);
  /// Forgets a sensor (e.g. after the stream was declared lost).
  void reset(std::uint32_t sensor_id) {
    last_.erase(sensor_id);
    candidate_.erase(sensor_id);
    restart_candidate_.erase(sensor_id);
  }
  /// Forgets every sensor (the participant started a new run).
  void resetAll() {
    last_.clear();
    started_.clear();
    candidate_.clear();
    restart_candidate_.clear();
  }

 private:
  struct Last {
    std::uint64_t seq;
    std::uint64_t time_ns;
  };
  /// Sensors seen in this run (a reset after a lost stream does not count the start again).
  std::set<std::uint32_t> started_;
  struct Candidate {
    std::uint64_t seq;
    std::uint64_t time_ns;
    int count;
    std::uint64_t first_seq;  ///< the sequence number of the chain's first sample
  };
  /// The forward-jump rule: nullopt to accept, or the rejection. On adoption, `first_seq` is
  /// the sequence number of the confirmed chain's first sample.
  std::optional<Rejection> checkJump(std::uint32_t sensor_id, std::uint64_t seq,
                                     std::uint64_t time_ns, std::uint64_t stream_latest_ns,
                                     Outcome& out, std::uint64_t& first_seq);
  /// The restart rule for a sample behind the stream: true when it confirms a restart.
  bool confirmsRestart(std::uint32_t sensor_id, std::uint64_t seq, std::uint64_t time_ns);
  /// A candidate continues from the previous one: sequence and time increasing (time within
  /// the jump tolerance, when there is one).
  bool continues(const Candidate& c, std::uint64_t seq, std::uint64_t time_ns) const;
  TimeJumpRule rule_;
  TimeReference* reference_{nullptr};
  std::map<std::uint32_t, Last> last_;
  std::map<std::uint32_t, Candidate> candidate_;
  std::map<std::uint32_t, Candidate> restart_candidate_;
};

}  // namespace navbus::bus

namespace navbus::bus {

struct StreamCounters;

/// The admission pipeline of one input topic: validate, check time/sequence per sensor, count
/// (accepted, rejected by reason, sequence gaps) and log each kind of rejection the first time
/// and every 1000th time after, and each listed sensor's first rejection, with the field and
/// value.
class StreamGate {
 public:
  StreamGate(std::string topic, StreamCounters& counters, ValidationLimits limits = {})
      : topic_(std::move(topic)), counters_(counters), limits_(limits) {}
  /// With the forward-jump rule, judged against the participant's shared time reference.
  StreamGate(std::string topic, StreamCounters& counters, TimeJumpRule rule,
             TimeReference* reference)
      : topic_(std::move(topic)), counters_(counters), tracker_(rule, reference) {}

  template <class Sample>
  bool admit(const Sample& sample, std::uint32_t sensor_id, std::uint64_t seq,
             std::uint64_t time_ns) {
    jump_candidate_ = 0;
    if (auto r = validate(sample, limits_)) {
      reject(*r, sensor_id);
      return false;
    }
    const SequenceTracker::Outcome o = tracker_.check(sensor_id, seq, time_ns);
    if (o.rejection) {
      jump_candidate_ = o.jump_candidate;
      reject(*o.rejection, sensor_id);
      return false;
    }
    noteSequence(o, sensor_id);
    source_restarted_ = o.source_restarted;
    jump_held_ = o.jump_held;
    return true;
  }

  /// The sample admitted last started a new run of its source (SequenceTracker::Outcome).
  bool sourceRestarted() const { return source_restarted_; }
  /// The sample refused last is a forward-jump candidate: its place in the chain
  /// (SequenceTracker::Outcome::jump_candidate), 0 for any other refusal.
  int jumpCandidate() const { return jump_candidate_; }
  /// The sample admitted last confirmed a forward jump: how many refused candidates before it
  /// belong to the chain (SequenceTracker::Outcome::jump_held).
  int jumpHeld() const { return jump_held_; }
  /// Counts `n` samples of the confirmed chain, refused as REJECT_TIME_JUMP when they came and
  /// held by the caller, as accepted after all.
  void admitHeld(std::uint32_t sensor_id, std::size_t n);

  /// Counts a rejection decided after admission (e.g. late for the sequencer).
  void reject(const Rejection& r, std::uint32_t sensor_id);
  /// Counts an element dropped from an accepted sample (a satellite of an epoch).
  void rejectElement(const Rejection& r, std::uint32_t sensor_id);
  /// Undoes the accepted count of a sample of `sensor_id` rejected after admission.
  void unaccept(std::uint32_t sensor_id);
  const std::string& topic() const { return topic_; }
  /// The topic's counters (a block's elements are received under their own topic's).
  StreamCounters& counters() { return counters_; }
  const ValidationLimits& limits() const { return limits_; }
  SequenceTracker& tracker() { return tracker_; }

 private:
  void noteSequence(const SequenceTracker::Outcome& o, std::uint32_t sensor_id);

  std::string topic_;
  StreamCounters& counters_;
  ValidationLimits limits_;
  SequenceTracker tracker_;
  bool source_restarted_{false};
  int jump_candidate_{0};
  int jump_held_{0};
};

}  // namespace navbus::bus
