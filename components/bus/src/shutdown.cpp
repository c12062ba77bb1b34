#include "navbus/bus/shutdown.hpp"

#include <pthread.h>
#include <csignal>

namespace navbus::bus {

namespace {
sigset_t shutdownSignals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}
}  // namespace

ShutdownSignal::ShutdownSignal() {
  sigset_t set = shutdownSignals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  waiter_ = std::thread([this, set] {
    int sig = 0;
    while (sigwait(&set, &sig) == 0) {
      if (stopping_.load()) {
        return;
      }
      signal_.store(sig);
      request();
    }
  });
}

ShutdownSignal::~ShutdownSignal() {
  stopping_.store(true);
  // Wake the waiter with a signal addressed to it alone; it is blocked, so sigwait takes it.
  pthread_kill(waiter_.native_handle(), SIGTERM);
  waiter_.join();
}

void ShutdownSignal::request() {
  requested_.store(true);
  condition_.set_trigger_value(true);
}

}  // namespace navbus::bus
