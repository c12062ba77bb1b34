// SIGINT/SIGTERM turned into a DDS guard condition, without work in a signal handler.
#pragma once

#include <atomic>
#include <thread>

#include <fastdds/dds/core/condition/GuardCondition.hpp>

namespace navbus::bus {

/// Blocks SIGINT and SIGTERM in the calling thread (and so in every thread created after it,
/// including Fast DDS's) and waits for them in a dedicated thread with sigwait(), which then
/// triggers `condition()`. Construct it first thing in main().
class ShutdownSignal {
 public:
  ShutdownSignal();
  ~ShutdownSignal();
  ShutdownSignal(const ShutdownSignal&) = delete;
  ShutdownSignal& operator=(const ShutdownSignal&) = delete;

  eprosima::fastdds::dds::GuardCondition& condition() { return condition_; }
  bool requested() const { return requested_.load(); }
  /// Which signal ended the run (0 if none).
  int signal() const { return signal_.load(); }
  /// Requests shutdown from inside the program (e.g. the scenario has ended).
  void request();

 private:
  eprosima::fastdds::dds::GuardCondition condition_;
  std::atomic<bool> requested_{false};
  std::atomic<int> signal_{0};
  std::atomic<bool> stopping_{false};
  std::thread waiter_;
};

}  // namespace navbus::bus
