// libFuzzer target: the CDR deserialization of every navbus topic type, as a participant's
// DataReader runs it on bytes from the wire, followed by the input validators and conversions
// the participants apply to what deserializes.
//
// Input: one selector byte (which type, modulo the number of types), then the serialized
// payload as it travels in a DATA submessage (4-byte encapsulation header, CDR body).
// Properties checked beyond "no crash, no leak, no undefined behaviour":
//  - deserialization, as the participants register the types (GuardedType), either succeeds
//    or reports failure: no exception escapes (the generated code alone lets Fast-CDR's out),
//  - what deserializes serializes again, and that serialization deserializes to the same bytes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include <navbus_idl/FaultPubSubTypes.h>
#include <navbus_idl/GnssPubSubTypes.h>
#include <navbus_idl/HealthPubSubTypes.h>
#include <navbus_idl/ImuPubSubTypes.h>
#include <navbus_idl/NavigationPubSubTypes.h>
#include <navbus_idl/StarTrackerPubSubTypes.h>

#include "navbus/bus/conversions.hpp"
#include "navbus/bus/guarded_type.hpp"
#include "navbus/bus/validation.hpp"
#include "navbus/core/integrity/glr.hpp"

namespace {

using eprosima::fastrtps::rtps::SerializedPayload_t;
using navbus::bus::ValidationLimits;

void check(bool condition) {
  if (!condition) std::abort();  // a property violation is a finding, like a crash
}

/// What the participants do with a deserialized sample (nothing for the types they only log).
void admit(const navbus::ImuIncrement& s, const ValidationLimits& l) {
  if (!navbus::bus::validate(s, l)) (void)navbus::bus::toCore(s);
}
void admit(const navbus::ImuIncrementBlock& s, const ValidationLimits& l) {
  if (navbus::bus::validate(s, l)) return;
  for (const navbus::ImuIncrement& increment : s.increments()) admit(increment, l);
}
void admit(const navbus::ImuRawBlock& s, const ValidationLimits& l) {
  (void)navbus::bus::validate(s, l);
}
void admit(const navbus::GnssObservationEpoch& s, const ValidationLimits& l) {
  if (navbus::bus::validate(s, l)) return;
  const auto dropped = navbus::bus::screenSatellites(s, l);
  (void)navbus::bus::toCore(s, dropped);
}
void admit(const navbus::GnssFix& s, const ValidationLimits& l) {
  if (!navbus::bus::validate(s, l)) (void)navbus::bus::toCore(s);
}
void admit(const navbus::StarTrackerAttitude& s, const ValidationLimits& l) {
  if (!navbus::bus::validate(s, l)) (void)navbus::bus::toCore(s);
}
void admit(const navbus::FilterDiagnostics& s, const ValidationLimits& l) {
  if (navbus::bus::validate(s, l)) return;
  navbus::core::GlrEpoch epoch;
  (void)navbus::bus::toGlrEpoch(s, epoch);
}
template <class Sample>
void admit(const Sample&, const ValidationLimits&) {}

template <class PubSubType>
std::vector<unsigned char> bytesOf(PubSubType& type, void* sample) {
  const std::uint32_t size = type.getSerializedSizeProvider(sample)();
  SerializedPayload_t payload(size);
  check(type.serialize(sample, &payload));
  return {payload.data, payload.data + payload.length};
}

template <class PubSubType>
void fuzzType(const std::uint8_t* data, std::size_t size) {
  using Sample = typename PubSubType::type;
  navbus::bus::GuardedType<PubSubType> type;
  SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  if (size > 0) std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  Sample sample;
  if (!type.deserialize(&payload, &sample)) return;
  admit(sample, ValidationLimits{});
  // Round trip: serialize(deserialize(serialize(s))) == serialize(s).
  const std::vector<unsigned char> first = bytesOf(type, &sample);
  SerializedPayload_t again(static_cast<std::uint32_t>(first.size()));
  std::memcpy(again.data, first.data(), first.size());
  again.length = static_cast<std::uint32_t>(first.size());
  Sample copy;
  check(type.deserialize(&again, &copy));
  check(bytesOf(type, &copy) == first);
}

using Fuzz = void (*)(const std::uint8_t*, std::size_t);
constexpr Fuzz kTypes[] = {
    fuzzType<navbus::ImuIncrementPubSubType>,
    fuzzType<navbus::ImuRawBlockPubSubType>,
    fuzzType<navbus::GnssObservationEpochPubSubType>,
    fuzzType<navbus::GnssFixPubSubType>,
    fuzzType<navbus::StarTrackerAttitudePubSubType>,
    fuzzType<navbus::NavigationSolutionPubSubType>,
    fuzzType<navbus::FilterDiagnosticsPubSubType>,
    fuzzType<navbus::FaultDecisionPubSubType>,
    fuzzType<navbus::FilterCommandPubSubType>,
    fuzzType<navbus::HealthPubSubType>,
    fuzzType<navbus::ImuIncrementBlockPubSubType>,
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  constexpr std::size_t kCount = sizeof(kTypes) / sizeof(kTypes[0]);
  kTypes[data[0] % kCount](data + 1, size - 1);
  return 0;
}
