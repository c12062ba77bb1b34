// A topic type whose deserialization cannot throw: bytes from the wire that are not a valid
// CDR encoding of the type are refused, and counted, instead of ending the process.
//
// Why: the generated TopicDataType::deserialize lets Fast-CDR's exceptions out (a bad
// encapsulation identifier raises BadParamException; found by tests/fuzz/fuzz_topics.cpp).
// Fast DDS 2.9 calls it in DataReader::take (the participant's thread) and, for a keyed sample
// sent without its key hash, in its own receive thread (DataReaderHistory computing the
// instance key), where an exception terminates the process. Returning false instead makes
// Fast DDS drop the sample (ReadTakeCommand removes it from the reader's history).
#pragma once

#include <atomic>
#include <cstdint>

#include <fastcdr/exceptions/Exception.h>
#include <fastdds/dds/topic/TopicDataType.hpp>

namespace navbus::bus {

/// Failed deserializations of a type in the participant's own take calls.
class MalformedCounter {
 public:
  virtual ~MalformedCounter() = default;
  /// Payloads refused while a TakeScope was open, since the last call; resets the count.
  virtual std::uint64_t takeMalformed() = 0;

  /// Open while the participant takes samples on this thread: failures then count (the same
  /// payload refused earlier by the receive thread's key computation is not counted twice).
  class TakeScope {
   public:
    TakeScope() { active() = true; }
    ~TakeScope() { active() = false; }
    TakeScope(const TakeScope&) = delete;
    TakeScope& operator=(const TakeScope&) = delete;
    static bool open() { return active(); }

   private:
    static bool& active() {
      thread_local bool taking = false;
      return taking;
    }
  };
};

template <class PubSubType>
class GuardedType final : public PubSubType, public MalformedCounter {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    bool ok = false;
    try {
      ok = PubSubType::deserialize(payload, data);
    } catch (const eprosima::fastcdr::exception::Exception&) {
      ok = false;
    }
    if (!ok && TakeScope::open()) malformed_.fetch_add(1, std::memory_order_relaxed);
    return ok;
  }

  std::uint64_t takeMalformed() override {
    return malformed_.exchange(0, std::memory_order_relaxed);
  }

 private:
  std::atomic<std::uint64_t> malformed_{0};
};

}  // namespace navbus::bus
