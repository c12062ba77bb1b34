#include "frame_prefetcher.hpp"

namespace navbus::tool {

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
      batch.reserve(kBatch);
      while (batch.size() < kBatch && source.index() < total) batch.push_back(source.next());
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

std::optional<sim::SensorFrame> FramePrefetcher::next() {
  if (position_ == current_.size()) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !ready_.empty() || done_; });
    if (ready_.empty()) {
      if (error_) std::rethrow_exception(error_);
      return std::nullopt;
    }
    current_ = std::move(ready_.front());
    ready_.pop_front();
    position_ = 0;
    lock.unlock();
    changed_.notify_all();
  }
  return std::move(current_[position_++]);
}

}  // namespace navbus::tool
