#include "navbus/bus/streams.hpp"

namespace navbus::bus {

namespace {
constexpr bool kindsInOrder() {
  for (std::size_t i = 0; i < kStreamKinds.size(); ++i) {
    if (static_cast<std::size_t>(kStreamKinds[i].kind) != i) return false;
  }
  return true;
}
static_assert(kindsInOrder(), "kStreamKinds: row i must describe StreamKind i");
}  // namespace

const SensorTopic* findSensorTopic(std::string_view topic) {
  for (const SensorTopic& row : kSensorTopics) {
    if (topic == row.topic) return &row;
  }
  return nullptr;
}

}  // namespace navbus::bus
