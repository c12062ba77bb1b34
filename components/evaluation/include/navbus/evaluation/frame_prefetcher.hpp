// Runs the simulator ahead of the filter on a second thread: `navbus offline` and `montecarlo`
// spend about a third of their time in the simulator, which does not depend on the filter.
// Frames come out in the order the simulator made them, so the run is the same as without
// the thread (bit for bit); frames travel in batches to keep the hand-over rare, and the
// consumer hands its batches back, so that the producer fills the same frames again: their
// sample buffers are allocated once per run, not once per frame on one thread and freed on
// the other.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "navbus/sim/scenario_source.hpp"

namespace navbus::evaluation {

class FramePrefetcher {
 public:
  /// Starts producing `total` frames of `source` (which must outlive this object).
  FramePrefetcher(sim::ScenarioSource& source, std::int64_t total);
  ~FramePrefetcher();
  FramePrefetcher(const FramePrefetcher&) = delete;
  FramePrefetcher& operator=(const FramePrefetcher&) = delete;

  /// The next frame, valid until the next call; nullptr after the last. Rethrows what the
  /// simulator threw.
  const sim::SensorFrame* next();

 private:
  static constexpr std::size_t kBatch = 256;     ///< frames per hand-over
  static constexpr std::size_t kMaxBatches = 8;  ///< batches ahead of the filter at most
  void produce(sim::ScenarioSource& source, std::int64_t total);

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::vector<sim::SensorFrame>> ready_;
  std::vector<std::vector<sim::SensorFrame>> spare_;  ///< consumed batches, to be filled again
  bool done_{false};      ///< the producer has handed over its last batch
  bool stopping_{false};  ///< the consumer is gone
  std::exception_ptr error_;
  std::vector<sim::SensorFrame> current_;
  std::size_t position_{0};
  std::thread thread_;
};

}  // namespace navbus::evaluation
