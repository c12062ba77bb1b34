#include "navbus/evaluation/frame_prefetcher.hpp"

#include <algorithm>

namespace navbus::evaluation {

FramePrefetcher::FramePrefetcher(sim::ScenarioSource& source, std::int64_t total)
    : thread_([this, &source, total] { produce(source, total); }) {}

FramePrefetcher::~FramePrefetcher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void FramePrefetcher::produce(sim::ScenarioSource& source, std::int64_t total) {
  try {
    while (source.index() < total) {
      std::vector<sim::SensorFrame> batch;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!spare_.empty()) {
          batch = std::move(spare_.back());
          spare_.pop_back();
        }
      }
      const auto frames = static_cast<std::size_t>(
          std::min<std::int64_t>(static_cast<std::int64_t>(kBatch), total - source.index()));
      batch.resize(frames);
      for (sim::SensorFrame& f : batch) source.next(f);
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return ready_.size() < kMaxBatches || stopping_; });
      if (stopping_) return;
      ready_.push_back(std::move(batch));
      lock.unlock();
      changed_.notify_all();
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = std::current_exception();
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  changed_.notify_all();
}

const sim::SensorFrame* FramePrefetcher::next() {
  if (position_ == current_.size()) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!current_.empty()) spare_.push_back(std::move(current_));
    current_.clear();
    changed_.wait(lock, [this] { return !ready_.empty() || done_; });
    if (ready_.empty()) {
      if (error_) std::rethrow_exception(error_);
      return nullptr;
    }
    current_ = std::move(ready_.front());
    ready_.pop_front();
    position_ = 0;
    lock.unlock();
    changed_.notify_all();
  }
  return &current_[position_++];
}

}  // namespace navbus::evaluation
