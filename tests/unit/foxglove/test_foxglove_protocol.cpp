// The Foxglove bridge without a network: the protocol's messages as the specification
// (foxglove/ws-protocol docs/spec.md) gives them, a client's requests read and refused with the
// field and the value, and one client's session: subscriptions, bounded queues whose drops are
// counted per channel, control messages before data, channels that go. tests/foxglove checks
// the server with Foxglove's own client.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "navbus/foxglove/client_session.hpp"
#include "navbus/foxglove/protocol.hpp"

using namespace navbus::foxglove;
using nlohmann::json;

namespace {

Payload bytesPayload(std::uint8_t v) {
  return std::make_shared<const std::vector<std::uint8_t>>(std::vector<std::uint8_t>{v, v});
}

std::string refusalOf(const std::string& text) {
  const ClientRequest r = parseClientMessage(text);
  const auto* refused = std::get_if<RefusedRequest>(&r);
  return refused == nullptr ? "accepted" : refused->reason;
}

const auto kChannels0To9 = [](std::uint32_t id) { return id < 10; };

}  // namespace

TEST(FoxgloveProtocol, ServerMessagesCarryTheSpecificationsFields) {
  const json info = json::parse(serverInfoJson("navbus", "123"));
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_EQ(info["name"], "navbus");
  EXPECT_TRUE(info["capabilities"].is_array());
  EXPECT_EQ(info["sessionId"], "123");
  const json ad =
      json::parse(advertiseJson({{7, "navbus/nav/solution", "cdr", "navbus::NavigationSolution",
                                  "module navbus {};", "omgidl"}}));
  ASSERT_EQ(ad["channels"].size(), 1u);
  EXPECT_EQ(ad["op"], "advertise");
  EXPECT_EQ(ad["channels"][0]["id"], 7);
  EXPECT_EQ(ad["channels"][0]["encoding"], "cdr");
  EXPECT_EQ(ad["channels"][0]["schemaName"], "navbus::NavigationSolution");
  EXPECT_EQ(ad["channels"][0]["schemaEncoding"], "omgidl");
  EXPECT_EQ(json::parse(unadvertiseJson({7, 9}))["channelIds"], json::array({7, 9}));
  const json status = json::parse(statusJson(StatusLevel::kError, "bad"));
  EXPECT_EQ(status["level"], 2);
  // Message Data: opcode 0x01, subscription id and receive time little-endian.
  const auto h = messageDataHeader(0x01020304u, 0x1122334455667788ull);
  const std::vector<std::uint8_t> expected{0x01, 0x04, 0x03, 0x02, 0x01, 0x88, 0x77,
                                           0x66, 0x55, 0x44, 0x33, 0x22, 0x11};
  EXPECT_EQ(h, expected);
}

TEST(FoxgloveProtocol, ClientRequestsAreReadOrRefusedNamingTheFieldAndTheValue) {
  const ClientRequest sub = parseClientMessage(
      R"({"op":"subscribe","subscriptions":[{"id":3,"channelId":4},{"id":4294967295,"channelId":0}]})");
  ASSERT_TRUE(std::holds_alternative<SubscribeRequest>(sub));
  const auto& s = std::get<SubscribeRequest>(sub).subscriptions;
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].id, 3u);
  EXPECT_EQ(s[0].channel_id, 4u);
  EXPECT_EQ(s[1].id, 4294967295u);
  const ClientRequest unsub = parseClientMessage(R"({"op":"unsubscribe","subscriptionIds":[3]})");
  ASSERT_TRUE(std::holds_alternative<UnsubscribeRequest>(unsub));
  EXPECT_EQ(std::get<UnsubscribeRequest>(unsub).subscription_ids, std::vector<std::uint32_t>{3});

  EXPECT_EQ(refusalOf("{oops"), "not JSON: \"{oops\"");
  EXPECT_EQ(refusalOf("42"), "not a JSON object: 42");
  EXPECT_EQ(refusalOf(R"({"subscriptions":[]})"), "no field 'op'");
  EXPECT_EQ(refusalOf(R"({"op":7})"), "op: 7 is not a string");
  EXPECT_NE(refusalOf(R"({"op":"advertise","channels":[]})").find("\"advertise\" is not supported"),
            std::string::npos);
  EXPECT_EQ(refusalOf(R"({"op":"subscribe"})"), "subscribe: no field 'subscriptions'");
  EXPECT_EQ(refusalOf(R"({"op":"subscribe","subscriptions":{}})"),
            "subscribe: subscriptions: {} is not an array");
  EXPECT_EQ(refusalOf(R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})"),
            "subscribe: subscriptions[0].id: 4294967296 is not an unsigned 32-bit integer");
  EXPECT_EQ(refusalOf(R"({"op":"subscribe","subscriptions":[{"id":1}]})"),
            "subscribe: subscriptions[0]: no field 'channelId'");
  EXPECT_EQ(refusalOf(R"({"op":"unsubscribe","subscriptionIds":["a"]})"),
            "unsubscribe: subscriptionIds[0]: \"a\" is not an unsigned 32-bit integer");
  // A long value is quoted cut, not whole.
  const std::string refusal = refusalOf("{\"op\":\"" + std::string(5000, 'x') + "\"}");
  EXPECT_LT(refusal.size(), 200u);
}

TEST(FoxgloveSession, SubscribedChannelsGetFramesWithTheirSubscriptionId) {
  ClientSession s(4, 8);
  s.handleText(R"({"op":"subscribe","subscriptions":[{"id":11,"channelId":2}]})", kChannels0To9);
  EXPECT_EQ(s.subscriptions(), 1u);
  EXPECT_FALSE(s.next().has_value());            // nothing refused, nothing offered
  EXPECT_FALSE(s.offer(3, 1, bytesPayload(1)));  // not subscribed
  EXPECT_TRUE(s.offer(2, 99, bytesPayload(5)));
  const auto out = s.next();
  ASSERT_TRUE(out.has_value());
  const auto& frame = std::get<DataFrame>(*out);
  EXPECT_EQ(frame.header, messageDataHeader(11, 99));
  EXPECT_EQ((*frame.payload)[0], 5);
  // Unsubscribed: no more frames, the queue gone.
  s.offer(2, 100, bytesPayload(6));
  s.handleText(R"({"op":"unsubscribe","subscriptionIds":[11]})", kChannels0To9);
  EXPECT_FALSE(s.next().has_value());
  EXPECT_EQ(s.subscriptions(), 0u);
}

TEST(FoxgloveSession, AFullQueueDropsItsOldestFrameAndCountsItForTheChannel) {
  ClientSession s(3, 8);
  s.handleText(
      R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":4},{"id":2,"channelId":5}]})",
      kChannels0To9);
  for (std::uint8_t i = 0; i < 10; ++i) s.offer(4, i, bytesPayload(i));
  s.offer(5, 50, bytesPayload(50));
  EXPECT_EQ(s.counters().frames_dropped, 7u);
  EXPECT_EQ(s.counters().dropped_by_channel.at(4), 7u);
  EXPECT_EQ(s.counters().dropped_by_channel.count(5), 0u);
  // The newest three of channel 4 remain, served in turn with channel 5's.
  std::vector<int> served;
  while (auto out = s.next()) served.push_back((*std::get<DataFrame>(*out).payload)[0]);
  EXPECT_EQ(served, (std::vector<int>{7, 50, 8, 9}));
}

TEST(FoxgloveSession, RefusalsAreStatusesAndControlMessagesGoFirst) {
  ClientSession s(2, 3);
  s.handleText(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]})", kChannels0To9);
  s.offer(1, 1, bytesPayload(1));
  s.handleText(R"({"op":"subscribe","subscriptions":[{"id":2,"channelId":42}]})", kChannels0To9);
  s.handleText(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":3}]})", kChannels0To9);
  s.handleText(R"({"op":"subscribe","subscriptions":[{"id":9,"channelId":1}]})", kChannels0To9);
  s.handleBinary();  // the fourth refusal: the text queue holds 3
  EXPECT_EQ(s.counters().requests_refused, 4u);
  EXPECT_EQ(s.counters().statuses_dropped, 1u);
  std::vector<std::string> messages;
  for (int i = 0; i < 3; ++i) {
    const auto out = s.next();
    ASSERT_TRUE(out.has_value());
    const json status = json::parse(std::get<std::string>(*out));
    EXPECT_EQ(status["level"], 2);
    messages.push_back(status["message"]);
  }
  EXPECT_EQ(messages[0], "subscribe: channel 42 is not advertised");
  EXPECT_EQ(messages[1], "subscribe: subscription id 1 is in use");
  EXPECT_EQ(messages[2], "subscribe: channel 1 is already subscribed (subscription 1)");
  ASSERT_TRUE(std::holds_alternative<DataFrame>(*s.next()));
  // A server message that does not fit any more: the session must end (it would miss it).
  for (int i = 0; i < 3; ++i) s.pushText("{}");
  EXPECT_FALSE(s.overflowed());
  s.pushText("{}");
  EXPECT_TRUE(s.overflowed());
}

TEST(FoxgloveSession, AChannelThatGoesTakesItsSubscriptionAndItsQueue) {
  ClientSession s(4, 8);
  s.handleText(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":2}]})", kChannels0To9);
  s.offer(2, 1, bytesPayload(1));
  s.channelGone(2);
  EXPECT_FALSE(s.next().has_value());
  EXPECT_FALSE(s.offer(2, 2, bytesPayload(2)));
  // The id is free again, for a channel that came back.
  s.handleText(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":2}]})", kChannels0To9);
  EXPECT_EQ(s.subscriptions(), 1u);
  EXPECT_EQ(s.counters().requests_refused, 0u);
}
