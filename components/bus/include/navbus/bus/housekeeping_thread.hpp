// A thread that runs a task every period until it is destroyed, at the normal scheduling class
// (SCHED_OTHER) even in a process given a real-time one: housekeeping (the shared-memory
// reclaim's directory scans, file locks and allocations) that must neither run on the processing
// thread nor preempt it. Named "navbus-housekp" (in /proc/PID/task/TID/comm).
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace navbus::bus {

class HousekeepingThread {
 public:
  HousekeepingThread(std::chrono::nanoseconds period, std::function<void()> task);
  ~HousekeepingThread();  ///< stops the thread (at once, not after the period) and joins it
  HousekeepingThread(const HousekeepingThread&) = delete;
  HousekeepingThread& operator=(const HousekeepingThread&) = delete;

  static constexpr const char* kThreadName = "navbus-housekp";

 private:
  void run();

  std::chrono::nanoseconds period_;
  std::function<void()> task_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_{false};
  std::thread thread_;  ///< last: started once the members above exist
};

}  // namespace navbus::bus
