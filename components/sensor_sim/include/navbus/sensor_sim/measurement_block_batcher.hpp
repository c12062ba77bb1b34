// Packs one sensor's epochs, fixes or attitudes into blocks for fast pacing
// (GnssObservationEpochBlock, GnssFixBlock, StarTrackerAttitudeBlock): as ImuBlockBatcher does
// for the increments, the same measurements in fewer DDS samples. The publisher fills the
// blocks of the frames an increment block covers and writes them with it.
#pragma once

#include <cstdint>
#include <utility>

#include "navbus/bus/streams.hpp"

namespace navbus::sensor_sim {

template <class Block>
class MeasurementBlockBatcher {
 public:
  using Traits = bus::SensorBlock<Block>;
  using Element = typename Traits::Element;

  /// Appends an element (of one sensor); false, adding nothing, when the pending block holds
  /// its IDL bound already: write take() first, then add again.
  bool add(const Element& element) {
    auto& elements = Traits::elements(pending_);
    if (elements.size() >= Traits::kMaxElements) return false;
    if (elements.empty())
      Traits::setSensorId(pending_, bus::SensorMessage<Element>::sensorId(element));
    elements.push_back(element);
    return true;
  }
  bool empty() const { return Traits::elements(pending_).empty(); }
  /// The pending block, numbered (1 for the first block, +1 per block), leaving none pending.
  Block take() {
    pending_.seq(++blocks_);
    Block out = std::move(pending_);
    pending_ = Block();
    return out;
  }

 private:
  Block pending_;
  std::uint64_t blocks_{0};
};

}  // namespace navbus::sensor_sim
