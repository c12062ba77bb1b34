#include "navbus/core/ins/output_predictor.hpp"

#include <cmath>

namespace navbus::core {

OutputPredictor::OutputPredictor(earth::GravityModel gravity, std::size_t max_buffered)
    : gravity_(gravity), max_buffered_(max_buffered), buffered_(max_buffered), ins_(gravity) {}

void OutputPredictor::reset() {
  anchor_.reset();
  buffered_.clear();
  ins_ = StrapdownNed(gravity_);
  continuous_ = false;
}

void OutputPredictor::setAnchor(const OutputAnchor& anchor) {
  anchor_ = anchor;
  while (!buffered_.empty() && buffered_.front().time_ns <= anchor.state.time_ns)
    buffered_.pop_front();
  repropagate();
}

void OutputPredictor::repropagate() {
  ins_ = StrapdownNed(gravity_);
  ins_.initialize(anchor_->state);
  continuous_ = true;
  for (std::size_t k = 0; k < buffered_.size(); ++k) {
    if (!step(buffered_[k])) {
      continuous_ = false;  // a gap after the anchor: no output until the next anchor
      return;
    }
  }
}

bool OutputPredictor::step(const ImuIncrement& raw) {
  const auto interval_ns = static_cast<std::int64_t>(std::llround(raw.interval_s * 1e9));
  const std::int64_t start_ns = raw.time_ns - interval_ns;
  // The same continuity rule as the engine: the interval starts at the state time (half an
  // interval of jitter allowed).
  if (std::llabs(start_ns - ins_.state().time_ns) > interval_ns / 2) return false;
  ins_.propagate(anchor_->correction.applied(raw));
  return true;
}

std::optional<NavState> OutputPredictor::addIncrement(const ImuIncrement& inc) {
  if (anchor_ && inc.time_ns <= anchor_->state.time_ns) {
    ++counters_.before_anchor;
    return std::nullopt;
  }
  if (!buffered_.empty() && inc.time_ns <= buffered_.back().time_ns) {
    ++counters_.not_after_previous;
    return std::nullopt;
  }
  if (buffered_.size() >= max_buffered_) {
    ++counters_.overflow;
    buffered_.pop_front();  // the filter lags by more than the buffer: the oldest go
  }
  buffered_.push_back(inc);
  if (!anchor_ || !continuous_) return std::nullopt;
  if (!step(inc)) {
    ++counters_.gaps;
    continuous_ = false;
    return std::nullopt;
  }
  ++counters_.outputs;
  return ins_.state();
}

}  // namespace navbus::core
