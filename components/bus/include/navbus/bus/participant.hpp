// The participant skeleton shared by every navbus executable: entities created from QoS
// profiles, one waitset loop (so handlers never run concurrently), timers, clean shutdown on
// SIGINT/SIGTERM, and periodic health publication.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/core/status/DeadlineMissedStatus.hpp>
#include <fastdds/dds/core/status/LivelinessChangedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include <navbus_idl/HealthPubSubTypes.h>

#include "navbus/bus/dds_context.hpp"
#include "navbus/bus/health.hpp"
#include "navbus/bus/housekeeping_thread.hpp"
#include "navbus/bus/realtime.hpp"
#include "navbus/bus/shutdown.hpp"
#include "navbus/bus/stream_end.hpp"

namespace navbus::bus {

/// A writer bound to its sample type; counts what it publishes in the participant's health.
template <class Sample>
class Writer {
 public:
  Writer() = default;
  Writer(eprosima::fastdds::dds::DataWriter* writer, HealthCounters* health)
      : writer_(writer), health_(health) {}
  /// Returns false (and logs) if the sample could not be written.
  bool write(const Sample& sample) {
    if (tryWrite(sample)) return true;
    logWriteFailure();
    return false;
  }
  /// Writes without losing the sample to a reader that fell behind. A reliable KEEP_ALL
  /// writer's write() fails once its history stayed full for the profile's max_blocking_time:
  /// a matched reader has not acknowledged. The write is then tried again, for as long as a
  /// reader is matched and `stopping()` is false; `waits` counts the retries. A failure with
  /// no reader matched is not flow control: after one more try, it returns false (and logs).
  template <class Stopping>
  bool writeWaitingForReaders(const Sample& sample, Stopping&& stopping, std::uint64_t& waits) {
    if (retryForReaders([&] { return tryWrite(sample); }, stopping, waits)) return true;
    logWriteFailure();
    return false;
  }
  /// Disposes the instance whose key `key_holder` carries: readers learn that the stream
  /// ended as announced (not lost). Returns false (and logs) on failure.
  bool dispose(const Sample& key_holder) {
    if (tryDispose(key_holder)) return true;
    logDisposeFailure();
    return false;
  }
  /// The dispose of a stream whose readers may be behind: a dispose is a change in the
  /// writer's history like a sample, refused while a reliable KEEP_ALL history stays full. It is
  /// tried again as writeWaitingForReaders tries a sample.
  template <class Stopping>
  bool disposeWaitingForReaders(const Sample& key_holder, Stopping&& stopping) {
    std::uint64_t waits = 0;
    if (retryForReaders([&] { return tryDispose(key_holder); }, stopping, waits)) return true;
    logDisposeFailure();
    return false;
  }
  /// Waits until every matched reliable reader acknowledged every change written, for as long
  /// as a reader is matched and `stopping()` is false (a reader far behind takes as long as it
  /// takes, as the writes waited for it). False, and a warning, if it stopped waiting first.
  template <class Stopping>
  bool waitForAcknowledgments(Stopping&& stopping) {
    if (writer_ == nullptr) return false;
    const eprosima::fastrtps::Duration_t poll(1, 0);
    while (writer_->wait_for_acknowledgments(poll) != ReturnCode_t::RETCODE_OK) {
      if (stopping() || matchedReaders() == 0) {
        spdlog::warn("'{}': not every reader acknowledged what was written ({})",
                     writer_->get_topic()->get_name(), stopping() ? "stopped" : "no reader left");
        return false;
      }
    }
    return true;
  }
  eprosima::fastdds::dds::DataWriter* raw() { return writer_; }
  std::size_t matchedReaders() const;

 private:
  /// Tries `attempt` (a write or a dispose that a full history refused) again for as long as a
  /// reader is matched and `stopping()` is false, counting the retries in `waits`; with no
  /// reader left, once more. False if it gave up.
  template <class Attempt, class Stopping>
  bool retryForReaders(Attempt&& attempt, Stopping&& stopping, std::uint64_t& waits) {
    bool readers_left = false;
    while (!attempt()) {
      if (stopping() || readers_left) return false;
      readers_left = matchedReaders() == 0;
      ++waits;
    }
    return true;
  }
  bool tryWrite(const Sample& sample) {
    if (writer_ == nullptr || !writer_->write(const_cast<Sample*>(&sample))) return false;
    health_->countPublished();
    return true;
  }
  bool tryDispose(const Sample& key_holder) {
    return writer_ != nullptr &&
           writer_->dispose(const_cast<Sample*>(&key_holder),
                            eprosima::fastrtps::rtps::c_InstanceHandle_Unknown) ==
               ReturnCode_t::RETCODE_OK;
  }
  void logDisposeFailure() const {
    if (writer_ == nullptr) {
      spdlog::error("dispose on a writer that was never created");
    } else {
      spdlog::error("dispose on '{}' failed", writer_->get_topic()->get_name());
    }
  }
  void logWriteFailure() const {
    if (writer_ == nullptr) {
      spdlog::error("write on a writer that was never created");
    } else {
      spdlog::error("write on '{}' failed", writer_->get_topic()->get_name());
    }
  }

  eprosima::fastdds::dds::DataWriter* writer_{nullptr};
  HealthCounters* health_{nullptr};
};

struct ReaderCallbacks {
  std::function<void(const eprosima::fastdds::dds::RequestedDeadlineMissedStatus&)> on_deadline;
  std::function<void(const eprosima::fastdds::dds::LivelinessChangedStatus&)> on_liveliness;
  /// An instance was disposed by its writer (the stream ended as announced).
  std::function<void(const eprosima::fastrtps::rtps::InstanceHandle_t&)> on_disposed;
};

class Participant {
 public:
  struct Options {
    ParticipantOptions dds;
    std::chrono::milliseconds health_period{1000};
    /// False: no health reports on the bus (an inspection tool that must not show up in what
    /// it inspects); the counters are still kept.
    bool publish_health{true};
    /// Scheduling class, priority, CPU affinity and locked memory (realtime.hpp), applied
    /// before the DDS participant is created so that its threads inherit them.
    RealtimeOptions realtime;
  };

  Participant(const Options& options, ShutdownSignal& shutdown);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  DdsContext& dds() { return dds_; }
  HealthCounters& health() { return health_; }
  /// Sets the reported state; from then on the participant manages it (the skeleton no longer
  /// promotes STARTING to RUNNING by itself). Leaving STARTING for a processing state
  /// (RUNNING or DEGRADED) records the resume time and publishes health at once.
  void setState(navbus::ParticipantState state);
  navbus::ParticipantState state() const { return state_; }

  template <class PubSubType>
  Writer<typename PubSubType::type> createWriter(const std::string& topic_name,
                                                 const std::string& profile) {
    auto* topic = dds_.topic<PubSubType>(topic_name);
    return Writer<typename PubSubType::type>(dds_.createWriter(topic, profile), &health_);
  }

  /// Subscribes; `on_sample` gets every valid sample taken, in reception order. The skeleton
  /// counts `received`; the handler counts accepted / rejected after validating.
  template <class PubSubType>
  eprosima::fastdds::dds::DataReader* subscribe(
      const std::string& topic_name, const std::string& profile,
      std::function<void(const typename PubSubType::type&,
                         const eprosima::fastdds::dds::SampleInfo&)>
          on_sample,
      ReaderCallbacks callbacks = {}) {
    using Sample = typename PubSubType::type;
    auto* topic = dds_.topic<PubSubType>(topic_name);
    auto* reader = dds_.createReader(topic, profile);
    StreamCounters* counters = &health_.stream(topic_name);
    MalformedCounter* malformed = dds_.malformedCounter(topic->get_type_name());
    auto ends = std::make_shared<StreamEndCounter>();
    auto take_all = [reader, counters, malformed, topic_name, on_sample, ends,
                     on_disposed = callbacks.on_disposed]() {
      Sample sample;
      eprosima::fastdds::dds::SampleInfo info;
      {
        const MalformedCounter::TakeScope taking;
        while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
          const std::int64_t rtps_seq = info.sample_identity.sequence_number().to64long();
          if (info.valid_data) {
            ++counters->received;
            ends->taken(writerId(info), rtps_seq);
            on_sample(sample, info);
          } else if (info.instance_state ==
                     eprosima::fastdds::dds::NOT_ALIVE_DISPOSED_INSTANCE_STATE) {
            countMissedBeforeEnd(topic_name, *counters, ends->disposed(writerId(info), rtps_seq));
            if (on_disposed) on_disposed(info.instance_handle);
          }
        }
      }
      if (malformed != nullptr) countMalformed(topic_name, *counters, malformed->takeMalformed());
    };
    addReader(reader, topic_name, std::move(take_all), std::move(callbacks));
    return reader;
  }

  /// Calls `fn` after every round of reader dispatch: all samples available in the round have
  /// been handed over by then (the filter releases its ordered inputs here).
  void setAfterDispatch(std::function<void()> fn) { after_dispatch_ = std::move(fn); }

  /// Calls `fn` every `period` from the waitset loop (first call one period from now).
  void addTimer(std::chrono::nanoseconds period, std::function<void()> fn);

  /// Runs the waitset loop until shutdown is requested; publishes a last health report.
  void run();
  /// One loop iteration: waits at most `max_wait` (less if a timer is due), then handles
  /// readers and due timers. For participants that drive their own loop (the simulator).
  void spinOnce(std::chrono::nanoseconds max_wait);
  /// Spins for `duration`, or until stopped.
  void spinFor(std::chrono::nanoseconds duration);
  /// The data this participant wrote ended as announced (it disposed every stream it wrote):
  /// publishes a health report in STATE_ENDED at once, and keeps that state until it leaves.
  /// Health is reliable: a monitor whose best-effort reader of a stream lost the dispose learns
  /// the end from it (the fault manager's watchdog), before the writer leaves the bus.
  void announceDataEnded();
  /// Publishes the final health report (STOPPING, or ENDED after announceDataEnded()), then
  /// waits up to kFinishAcknowledgmentWait for the reliable readers to acknowledge everything
  /// this participant wrote, so that a reader that is behind (a recorder on a loaded machine)
  /// still gets it; logs a warning if they had not. run() does it by itself.
  void finish();
  static constexpr std::chrono::seconds kFinishAcknowledgmentWait{5};
  /// Asks the loop to end (from a handler).
  void stop() { shutdown_.request(); }
  bool stopping() const { return shutdown_.requested(); }

  /// Publishes a health report now.
  void publishHealth();

  /// Removes what crashed or killed Fast DDS participants left in /dev/shm
  /// (bus/shared_memory.hpp): at start, then every kShmReclaimPeriod on a housekeeping thread.
  static void reclaimSharedMemoryOfDeadParticipants();
  static constexpr std::chrono::seconds kShmReclaimPeriod{5};

 private:
  struct ReaderEntry {
    eprosima::fastdds::dds::DataReader* reader;
    std::string topic;
    bool is_input;  ///< live data (volatile durability), not others' health
    std::function<void()> take_all;
    ReaderCallbacks callbacks;
  };
  struct Timer {
    std::chrono::nanoseconds period;
    std::chrono::steady_clock::time_point next;
    std::function<void()> fn;
  };

  /// Counts `n` payloads of `topic` that did not deserialize (received and rejected as
  /// REJECT_MALFORMED; Fast DDS dropped them); logs the first and every 1000th.
  static void countMalformed(const std::string& topic, StreamCounters& counters, std::uint64_t n);
  /// Counts `n` samples of `topic` missed before the end its writer announced as sequence gaps
  /// (a best-effort reader that fell behind; stream_end.hpp) and logs them.
  static void countMissedBeforeEnd(const std::string& topic, StreamCounters& counters,
                                   std::uint64_t n);
  void addReader(eprosima::fastdds::dds::DataReader* reader, const std::string& topic,
                 std::function<void()> take_all, ReaderCallbacks callbacks);
  /// Deadline status, then every sample the reader holds.
  void dispatch(ReaderEntry& entry);
  /// Liveliness status (writers alive or gone).
  void dispatchLiveliness(ReaderEntry& entry);
  void runDueTimers();
  /// Sets the state; leaving STARTING for RUNNING or DEGRADED records Health::resume_ns (from
  /// the first input taken) and publishes a report at once.
  void changeState(navbus::ParticipantState state);
  /// Unmanaged participants: STARTING becomes RUNNING with the first input taken, or on the
  /// first loop iteration for a pure source (no input readers).
  void promoteIfProcessing();

  /// The last participant out removes what dead ones left in /dev/shm (reclaimIfHostIdle).
  /// Declared before dds_ so that it runs after the DDS entities are gone.
  struct ShmReclaimAtExit {
    ShmReclaimAtExit() = default;
    ShmReclaimAtExit(const ShmReclaimAtExit&) = delete;
    ShmReclaimAtExit& operator=(const ShmReclaimAtExit&) = delete;
    ~ShmReclaimAtExit();
  };

  ShutdownSignal& shutdown_;
  RealtimeGrant realtime_;  ///< before dds_: applied before the DDS participant exists
  ShmReclaimAtExit shm_reclaim_at_exit_;
  DdsContext dds_;
  HealthCounters health_;
  navbus::Health health_message_;  ///< reused by every report (no allocation once filled)
  bool publish_health_{true};
  navbus::ParticipantState state_{navbus::STATE_STARTING};
  bool state_managed_{false};
  /// When the first input sample (live data: no durable history, no others' health) was taken.
  std::optional<std::chrono::steady_clock::time_point> first_input_at_;
  eprosima::fastdds::dds::WaitSet waitset_;
  std::vector<std::unique_ptr<ReaderEntry>> readers_;
  std::vector<Timer> timers_;
  std::function<void()> after_dispatch_;
  Writer<navbus::Health> health_writer_;
  eprosima::fastdds::dds::ConditionSeq active_;
  /// The periodic shared-memory reclaim, off the processing thread. Last: stopped first.
  HousekeepingThread shm_reclaimer_;
};

template <class Sample>
std::size_t Writer<Sample>::matchedReaders() const {
  if (writer_ == nullptr) return 0;
  eprosima::fastdds::dds::PublicationMatchedStatus status;
  writer_->get_publication_matched_status(status);
  return static_cast<std::size_t>(status.current_count);
}

/// Nanoseconds of GPS time now (system clock, GPS-UTC leap seconds = 18 since 2017).
std::uint64_t gpsTimeNowNs();
/// Nanoseconds since the Unix epoch now.
std::uint64_t wallTimeNowNs();

}  // namespace navbus::bus
