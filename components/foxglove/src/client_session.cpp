#include "navbus/foxglove/client_session.hpp"

#include <type_traits>

namespace navbus::foxglove {

ClientSession::ClientSession(std::size_t frames_per_subscription, std::size_t max_texts)
    : frames_per_subscription_(frames_per_subscription), max_texts_(max_texts) {}

void ClientSession::refuse(const std::string& reason) {
  ++counters_.requests_refused;
  if (texts_.size() >= max_texts_) {
    ++counters_.statuses_dropped;
    return;
  }
  texts_.push_back(statusJson(StatusLevel::kError, reason));
}

void ClientSession::handleText(const std::string& text,
                               const std::function<bool(std::uint32_t)>& channel_exists) {
  const ClientRequest request = parseClientMessage(text);
  std::visit(
      [&](const auto& r) {
        using R = std::decay_t<decltype(r)>;
        if constexpr (std::is_same_v<R, SubscribeRequest>) {
          subscribe(r, channel_exists);
        } else if constexpr (std::is_same_v<R, UnsubscribeRequest>) {
          unsubscribe(r);
        } else {
          refuse(r.reason);
        }
      },
      request);
}

void ClientSession::handleBinary() {
  refuse("binary messages are not taken: this server has no clientPublish capability");
}

void ClientSession::subscribe(const SubscribeRequest& r,
                              const std::function<bool(std::uint32_t)>& channel_exists) {
  for (const Subscription& s : r.subscriptions) {
    if (!channel_exists(s.channel_id)) {
      refuse("subscribe: channel " + std::to_string(s.channel_id) + " is not advertised");
    } else if (channel_of_subscription_.count(s.id) != 0) {
      refuse("subscribe: subscription id " + std::to_string(s.id) + " is in use");
    } else if (subscription_of_channel_.count(s.channel_id) != 0) {
      refuse("subscribe: channel " + std::to_string(s.channel_id) +
             " is already subscribed (subscription " +
             std::to_string(subscription_of_channel_.at(s.channel_id)) + ")");
    } else {
      channel_of_subscription_[s.id] = s.channel_id;
      subscription_of_channel_[s.channel_id] = s.id;
      queued_[s.id];
    }
  }
}

void ClientSession::unsubscribe(const UnsubscribeRequest& r) {
  for (const std::uint32_t id : r.subscription_ids) {
    const auto it = channel_of_subscription_.find(id);
    if (it == channel_of_subscription_.end()) {
      refuse("unsubscribe: no subscription " + std::to_string(id));
      continue;
    }
    subscription_of_channel_.erase(it->second);
    channel_of_subscription_.erase(it);
    queued_.erase(id);
  }
}

bool ClientSession::offer(std::uint32_t channel_id, std::uint64_t receive_time_ns,
                          const Payload& payload) {
  const auto sub = subscription_of_channel_.find(channel_id);
  if (sub == subscription_of_channel_.end()) return false;
  std::deque<DataFrame>& q = queued_[sub->second];
  if (q.size() >= frames_per_subscription_) {
    q.pop_front();
    ++counters_.frames_dropped;
    ++counters_.dropped_by_channel[channel_id];
  }
  q.push_back({messageDataHeader(sub->second, receive_time_ns), payload});
  ++counters_.frames_queued;
  return true;
}

void ClientSession::pushText(std::string text) {
  if (texts_.size() >= max_texts_) {
    overflowed_ = true;  // an advertisement it would miss: the connection must end
    return;
  }
  texts_.push_back(std::move(text));
}

void ClientSession::channelGone(std::uint32_t channel_id) {
  const auto sub = subscription_of_channel_.find(channel_id);
  if (sub == subscription_of_channel_.end()) return;
  queued_.erase(sub->second);
  channel_of_subscription_.erase(sub->second);
  subscription_of_channel_.erase(sub);
}

std::optional<Outgoing> ClientSession::next() {
  if (!texts_.empty()) {
    Outgoing out = std::move(texts_.front());
    texts_.pop_front();
    return out;
  }
  // The subscriptions in turn, from the one after the last served.
  if (queued_.empty()) return std::nullopt;
  auto it = queued_.upper_bound(last_served_);
  for (std::size_t n = 0; n < queued_.size(); ++n, ++it) {
    if (it == queued_.end()) it = queued_.begin();
    if (it->second.empty()) continue;
    last_served_ = it->first;
    Outgoing out = std::move(it->second.front());
    it->second.pop_front();
    return out;
  }
  return std::nullopt;
}

}  // namespace navbus::foxglove
