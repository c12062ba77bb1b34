#include "navbus/bus/housekeeping_thread.hpp"

#include <pthread.h>
#include <sched.h>

#include <utility>

namespace navbus::bus {

HousekeepingThread::HousekeepingThread(std::chrono::nanoseconds period, std::function<void()> task)
    : period_(period), task_(std::move(task)), thread_([this] { run(); }) {}

HousekeepingThread::~HousekeepingThread() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void HousekeepingThread::run() {
  // Created by a thread of a real-time class, it inherited it: back to the normal class (a
  // lowering, which needs no privilege). The CPU affinity stays as inherited.
  const sched_param normal{};
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal);
  pthread_setname_np(pthread_self(), kThreadName);
  std::unique_lock<std::mutex> lock(mutex_);
  while (!wake_.wait_for(lock, period_, [this] { return stop_; })) {
    lock.unlock();
    task_();
    lock.lock();
  }
}

}  // namespace navbus::bus
