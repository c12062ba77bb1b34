#pragma once
// Samples refused as forward-jump candidates, kept until the samples after them decide.

#include <cstdint>
#include <map>
#include <vector>

#include "navbus/bus/validation.hpp"

namespace navbus::nav_filter {

/// The samples of one input that its gate refused as a forward time jump (REJECT_TIME_JUMP)
/// while the chain they start may still be confirmed (bus::TimeJumpRule). When the samples
/// after them confirm the jump, they are used as well: whether a stream's first samples count
/// as a jump depends on whether the other streams' earlier samples arrived first, and using
/// the whole chain makes the filter's input the same in either order. At most
/// TimeJumpRule::confirmations - 1 samples per sensor are kept.
template <class Sample>
class HeldSamples {
 public:
  /// After `gate` refused `sample` of `sensor_id`: keeps it if it is a jump candidate (a new
  /// chain replaces the sensor's earlier candidates).
  void afterRefusal(const bus::StreamGate& gate, std::uint32_t sensor_id, const Sample& sample) {
    const int place = gate.jumpCandidate();
    if (place == 0) return;
    std::vector<Sample>& chain = held_[sensor_id];
    if (place == 1) chain.clear();
    chain.push_back(sample);
  }

  /// After `gate` admitted a sample of `sensor_id`: the held samples that it confirmed, oldest
  /// first, counted as accepted by the gate. Candidates it did not confirm stay refused.
  std::vector<Sample> afterAdmission(bus::StreamGate& gate, std::uint32_t sensor_id) {
    auto it = held_.find(sensor_id);
    if (it == held_.end()) return {};
    std::vector<Sample> chain = std::move(it->second);
    held_.erase(it);
    const auto confirmed = static_cast<std::size_t>(gate.jumpHeld());
    if (confirmed == 0) return {};
    if (chain.size() > confirmed) chain.erase(chain.begin(), chain.end() - confirmed);
    gate.admitHeld(sensor_id, chain.size());
    return chain;
  }

  /// Forgets every candidate (the participant started a new run).
  void clear() { held_.clear(); }

 private:
  std::map<std::uint32_t, std::vector<Sample>> held_;
};

}  // namespace navbus::nav_filter
