// libFuzzer target: the Foxglove bridge's client handling (foxglove/client_session.hpp) on
// arbitrary client messages.
//
// Input: messages separated by 0x00 bytes; a message starting with 0x01 is a binary message,
// any other a text message. Between messages, one frame is offered on each of channels 0-3
// (channels 0-7 exist), and every second message the queues are drained.
// Properties beyond "no crash, no leak, no undefined behaviour": every queue stays within its
// bound; every text the session sends is a JSON object whose op is "status", "advertise" or
// "unadvertise"; a status is level 2 (error) and names the problem; a data frame carries a
// subscription id the session holds and the 13-byte header.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <nlohmann/json.hpp>

#include "navbus/foxglove/client_session.hpp"

namespace {

constexpr std::size_t kFramesPerSubscription = 4;
constexpr std::size_t kMaxTexts = 8;

[[noreturn]] void violated(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_foxglove: %s: %s\n", what, detail.c_str());
  std::abort();
}

void drain(navbus::foxglove::ClientSession& session) {
  std::size_t taken = 0;
  while (auto next = session.next()) {
    if (++taken > kMaxTexts + 8 * kFramesPerSubscription + 64)
      violated("queues", "more messages than the bounds allow");
    if (const auto* text = std::get_if<std::string>(&*next)) {
      const auto j = nlohmann::json::parse(*text, nullptr, false);
      if (j.is_discarded() || !j.is_object()) violated("text not a JSON object", *text);
      const std::string op = j.value("op", "");
      if (op != "status") violated("unexpected op", *text);
      if (j.value("level", -1) != 2 || j.value("message", "").empty())
        violated("status without level 2 and a message", *text);
    } else {
      const auto& frame = std::get<navbus::foxglove::DataFrame>(*next);
      if (frame.header.size() != navbus::foxglove::kMessageDataHeaderBytes ||
          frame.header[0] != 0x01 || !frame.payload)
        violated("data frame", "header or payload");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  navbus::foxglove::ClientSession session(kFramesPerSubscription, kMaxTexts);
  const auto exists = [](std::uint32_t id) { return id < 8; };
  const auto payload = std::make_shared<const std::vector<std::uint8_t>>(3, 7);
  std::size_t start = 0;
  for (std::size_t n = 0; start <= size; ++n) {
    std::size_t end = start;
    while (end < size && data[end] != 0) ++end;
    const std::string message(reinterpret_cast<const char*>(data + start), end - start);
    if (!message.empty() && message[0] == 0x01) {
      session.handleBinary();
    } else {
      session.handleText(message, exists);
    }
    for (std::uint32_t channel = 0; channel < 4; ++channel) session.offer(channel, n, payload);
    if (n % 2 == 1) drain(session);
    if (session.subscriptions() > 8) violated("subscriptions", "more than the channels");
    start = end + 1;
  }
  drain(session);
  return 0;
}
