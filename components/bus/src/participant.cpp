#include "navbus/bus/participant.hpp"

#include <algorithm>
#include <cstdlib>

#include <spdlog/spdlog.h>

#include "navbus/bus/gps_time.hpp"
#include "navbus/bus/shared_memory.hpp"
#include "navbus/bus/topics.hpp"

namespace navbus::bus {

namespace dds = eprosima::fastdds::dds;

Participant::Participant(const Options& options, ShutdownSignal& shutdown)
    : shutdown_(shutdown),
      realtime_(applyRealtime(options.realtime)),
      dds_(options.dds),
      health_(options.dds.name),
      publish_health_(options.publish_health),
      shm_reclaimer_(kShmReclaimPeriod, [] { reclaimSharedMemoryOfDeadParticipants(); }) {
  if (options.realtime.requested()) {
    if (options.realtime.lock_memory && !realtime_.memory_locked) {
      spdlog::warn(
          "realtime.lock_memory: mlockall succeeded but nothing is locked (VmLck 0 kB): a build "
          "with AddressSanitizer ignores mlockall");
    }
    spdlog::info("real-time: granted {}", realtime_.text());
  }
  waitset_.attach_condition(shutdown_.condition());
  if (publish_health_) {
    health_writer_ = createWriter<navbus::HealthPubSubType>(topic::kHealth, profile::kHealthWriter);
    addTimer(options.health_period, [this] { publishHealth(); });
  }
  reclaimSharedMemoryOfDeadParticipants();
}

namespace {

/// NAVBUS_SHM_RECLAIM=0 turns the reclaiming off.
bool shmReclaimOff() {
  static const bool off = [] {
    const char* v = std::getenv("NAVBUS_SHM_RECLAIM");
    return v != nullptr && std::string(v) == "0";
  }();
  return off;
}

/// Logs what was reclaimed, if anything.
void logReclaimed(const char* what, const ShmReclaimResult& r) {
  if (r.zombie_segments + r.zombie_ports == 0) return;
  spdlog::info("{}: {} segments and {} ports, {} bytes", what, r.zombie_segments, r.zombie_ports,
               r.bytes_reclaimed);
}

}  // namespace

Participant::ShmReclaimAtExit::~ShmReclaimAtExit() {
  if (shmReclaimOff()) return;
  logReclaimed("last shared-memory participant on the host: removed what dead ones left",
               reclaimIfHostIdle());
}

void Participant::reclaimSharedMemoryOfDeadParticipants() {
  if (shmReclaimOff()) return;
  logReclaimed("reclaimed the shared memory of dead Fast DDS participants", reclaimSharedMemory());
}

Participant::~Participant() {
  waitset_.detach_condition(shutdown_.condition());
  for (auto& entry : readers_) {
    waitset_.detach_condition(entry->reader->get_statuscondition());
  }
}

void Participant::countMissedBeforeEnd(const std::string& topic, StreamCounters& counters,
                                       std::uint64_t n) {
  if (n == 0) return;
  counters.sequence_gaps += n;
  spdlog::warn(
      "{}: the last {} sample(s) before the stream's announced end were not received "
      "(counted as sequence gaps)",
      topic, n);
}

void Participant::countMalformed(const std::string& topic, StreamCounters& counters,
                                 std::uint64_t n) {
  if (n == 0) return;
  counters.received += n;
  std::uint64_t& total = counters.rejected[navbus::REJECT_MALFORMED];
  const std::uint64_t before = total;
  total += n;
  if (before == 0 || before / 1000 != total / 1000) {
    spdlog::warn(
        "{}: {} payload(s) that do not deserialize as the topic's type dropped ({} so far)", topic,
        n, total);
  }
}

void Participant::addReader(dds::DataReader* reader, const std::string& topic,
                            std::function<void()> take_all, ReaderCallbacks callbacks) {
  // Others' health is no input, nor is the durable history a reader is handed on joining
  // (an earlier run's decisions and commands): the resume time runs from live data.
  const bool is_input = topic != topic::kHealth &&
                        reader->get_qos().durability().kind == dds::VOLATILE_DURABILITY_QOS;
  auto entry = std::make_unique<ReaderEntry>(
      ReaderEntry{reader, topic, is_input, std::move(take_all), std::move(callbacks)});
  dds::StatusMask mask = dds::StatusMask::data_available();
  mask << dds::StatusMask::requested_deadline_missed();
  mask << dds::StatusMask::liveliness_changed();
  reader->get_statuscondition().set_enabled_statuses(mask);
  waitset_.attach_condition(reader->get_statuscondition());
  readers_.push_back(std::move(entry));
}

void Participant::addTimer(std::chrono::nanoseconds period, std::function<void()> fn) {
  timers_.push_back(Timer{period, std::chrono::steady_clock::now() + period, std::move(fn)});
}

void Participant::dispatch(ReaderEntry& entry) {
  const dds::StatusMask changes = entry.reader->get_status_changes();
  if (changes.is_active(dds::StatusMask::requested_deadline_missed())) {
    dds::RequestedDeadlineMissedStatus status;
    entry.reader->get_requested_deadline_missed_status(status);
    health_.stream(entry.topic).deadline_misses +=
        static_cast<std::uint64_t>(status.total_count_change);
    if (entry.callbacks.on_deadline) {
      entry.callbacks.on_deadline(status);
    }
  }
  // Drain unconditionally rather than only when data_available is set: a sample that arrives
  // while the flag is being reset would otherwise wait for the next arrival, and a reliable
  // writer blocked on its full history sends none, a stall seen once in CI over shared memory.
  // Taking from an empty reader returns at once; the loop runs at least every 20-100 ms.
  if (first_input_at_ || !entry.is_input) {
    entry.take_all();
    return;
  }
  const StreamCounters& counters = health_.stream(entry.topic);
  const std::uint64_t before = counters.received;
  entry.take_all();
  if (counters.received > before) first_input_at_ = std::chrono::steady_clock::now();
}

void Participant::dispatchLiveliness(ReaderEntry& entry) {
  if (!entry.reader->get_status_changes().is_active(dds::StatusMask::liveliness_changed())) return;
  dds::LivelinessChangedStatus status;
  entry.reader->get_liveliness_changed_status(status);
  if (entry.callbacks.on_liveliness) entry.callbacks.on_liveliness(status);
}

void Participant::setState(navbus::ParticipantState state) {
  state_managed_ = true;
  changeState(state);
}

void Participant::changeState(navbus::ParticipantState state) {
  const bool starts_processing =
      state_ == navbus::STATE_STARTING &&
      (state == navbus::STATE_RUNNING || state == navbus::STATE_DEGRADED);
  state_ = state;
  if (!starts_processing) return;
  if (first_input_at_) {
    health_.setResumeNs(
        static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                       std::chrono::steady_clock::now() - *first_input_at_)
                                       .count()));
  }
  publishHealth();
}

void Participant::promoteIfProcessing() {
  if (state_managed_ || state_ != navbus::STATE_STARTING) return;
  const bool source_only =
      std::none_of(readers_.begin(), readers_.end(), [](const auto& r) { return r->is_input; });
  if (source_only || first_input_at_) changeState(navbus::STATE_RUNNING);
}

void Participant::runDueTimers() {
  const auto now = std::chrono::steady_clock::now();
  for (auto& t : timers_) {
    if (now >= t.next) {
      t.fn();
      // Skip missed periods instead of bursting to catch up.
      while (t.next <= now) {
        t.next += t.period;
      }
    }
  }
}

void Participant::spinFor(std::chrono::nanoseconds duration) {
  const auto end = std::chrono::steady_clock::now() + duration;
  for (auto now = std::chrono::steady_clock::now(); now < end && !stopping();
       now = std::chrono::steady_clock::now()) {
    spinOnce(end - now);
  }
}

void Participant::spinOnce(std::chrono::nanoseconds max_wait) {
  promoteIfProcessing();
  auto next = std::chrono::steady_clock::now() + max_wait;
  for (const auto& t : timers_) {
    next = std::min(next, t.next);
  }
  active_.clear();
  waitset_.wait(active_, toDdsDuration(next - std::chrono::steady_clock::now()));
  for (auto& entry : readers_) {
    // Poll every reader: a condition can be triggered again while we handle another one.
    dispatch(*entry);
  }
  // Writers leaving, once every reader's data is taken: a writer announces its streams' ends
  // (disposes, acknowledged by the reliable readers) before it leaves, and the end may sit in
  // another reader of this participant than the one that sees the writer gone (the fault
  // manager's parity reader and its watchdog's). Handled first, the departure declared the
  // streams lost (a replay under AddressSanitizer: three units LOST at the end).
  for (auto& entry : readers_) dispatchLiveliness(*entry);
  if (after_dispatch_) {
    after_dispatch_();
  }
  promoteIfProcessing();
  runDueTimers();
}

void Participant::run() {
  while (!shutdown_.requested()) {
    spinOnce(std::chrono::milliseconds(100));
  }
  finish();
}

void Participant::announceDataEnded() {
  state_ = navbus::STATE_ENDED;  // not STARTING: never promoted again
  publishHealth();
}

void Participant::finish() {
  if (state_ != navbus::STATE_ENDED) state_ = navbus::STATE_STOPPING;
  publishHealth();
  if (!dds_.waitForAcknowledgments(kFinishAcknowledgmentWait)) {
    spdlog::warn(
        "leaving the bus: not every reliable reader acknowledged what this participant wrote "
        "within {} s; the samples they had not taken are lost to them",
        kFinishAcknowledgmentWait.count());
  }
}

void Participant::publishHealth() {
  if (!publish_health_) return;
  health_.report(state_, wallTimeNowNs(), health_message_);
  health_writer_.write(health_message_);
}

std::uint64_t wallTimeNowNs() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

std::uint64_t gpsTimeNowNs() {
  return unixToGpsNs(wallTimeNowNs());
}

}  // namespace navbus::bus
