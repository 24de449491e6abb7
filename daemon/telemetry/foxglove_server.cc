#include "daemon/telemetry/foxglove_server.h"

#include <stdexcept>

#include "common/json_value.h"
#include "common/json_writer.h"

namespace cairn {

std::string FoxgloveServer::Base64(std::span<const uint8_t> b) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((b.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < b.size(); i += 3) {
    const uint32_t v = uint32_t{b[i]} << 16 | uint32_t{b[i + 1]} << 8 | b[i + 2];
    for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63];
  }
  if (i < b.size()) {
    const bool two = i + 1 < b.size();
    const uint32_t v = uint32_t{b[i]} << 16 | (two ? uint32_t{b[i + 1]} << 8 : 0);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

uint32_t FoxgloveServer::AddChannel(FoxgloveChannel channel) {
  channel.id = static_cast<uint32_t>(channels_.size() + 1);
  channels_.push_back(std::move(channel));
  return channels_.back().id;
}

Status FoxgloveServer::Start(const std::string& address, uint16_t port, size_t client_queue) {
  WebSocketServer::Callbacks cb;
  cb.on_open = [this](uint64_t c) { OnOpen(c); };
  cb.on_close = [this](uint64_t c) { OnClose(c); };
  cb.on_text = [this](uint64_t c, const std::string& t) { OnText(c, t); };
  std::string error;
  if (!server_.Start(address, port, "foxglove.websocket.v1", client_queue, std::move(cb), &error)) {
    return UnavailableError("live stream: " + error);
  }
  started_ = true;
  return Status::Ok();
}

void FoxgloveServer::Stop() {
  if (!started_) return;
  started_ = false;
  server_.Stop();
}

void FoxgloveServer::OnOpen(uint64_t client) {
  JsonWriter info(false);
  info.BeginObject().Field("op", "serverInfo").Field("name", name_);
  info.Key("capabilities").BeginArray().EndArray();
  info.Key("metadata").BeginObject().Field("software", "cairnd").EndObject();
  info.EndObject();
  server_.SendText(client, info.str());
  JsonWriter adv(false);
  adv.BeginObject().Field("op", "advertise").Key("channels").BeginArray();
  for (const FoxgloveChannel& c : channels_) {
    adv.BeginObject();
    adv.Field("id", c.id).Field("topic", c.topic).Field("encoding", c.encoding);
    adv.Field("schemaName", c.schema_name).Field("schema", c.schema);
    if (!c.schema_encoding.empty()) adv.Field("schemaEncoding", c.schema_encoding);
    adv.EndObject();
  }
  adv.EndArray().EndObject();
  server_.SendText(client, adv.str());
}

void FoxgloveServer::OnClose(uint64_t client) {
  std::lock_guard lock(mutex_);
  const auto it = subscriptions_.find(client);
  if (it == subscriptions_.end()) return;
  for (const auto& [sub, channel] : it->second) --subscriber_count_[channel];
  subscriptions_.erase(it);
}

void FoxgloveServer::SendStatus(uint64_t client, int level, const std::string& message) {
  JsonWriter s(false);
  s.BeginObject().Field("op", "status").Field("level", level).Field("message", message).EndObject();
  server_.SendText(client, s.str());
}

void FoxgloveServer::OnText(uint64_t client, const std::string& text) {
  // Client requests are untrusted input: anything malformed is answered with a status message.
  try {
    const JsonValue msg = JsonValue::Parse(text);
    const std::string& op = msg["op"].string();
    std::lock_guard lock(mutex_);
    auto& subs = subscriptions_[client];
    if (op == "subscribe") {
      for (const JsonValue& s : msg["subscriptions"].array()) {
        const auto sub = static_cast<uint32_t>(s["id"].number());
        const auto channel = static_cast<uint32_t>(s["channelId"].number());
        if (channel == 0 || channel > channels_.size()) {
          ++protocol_errors_;
          SendStatus(client, 2, "unknown channel " + std::to_string(channel));
          continue;
        }
        if (subs.count(sub) != 0) {
          ++protocol_errors_;
          SendStatus(client, 2, "subscription id " + std::to_string(sub) + " already in use");
          continue;
        }
        subs[sub] = channel;
        ++subscriber_count_[channel];
        if (const auto l = latched_.find(channel); l != latched_.end()) {
          for (const auto& [time, payload] : l->second.messages) {
            server_.SendBinary(client, MessageFrame(sub, time, {reinterpret_cast<const uint8_t*>(payload.data()),
                                                                payload.size()}));
          }
        }
      }
    } else if (op == "unsubscribe") {
      for (const JsonValue& s : msg["subscriptionIds"].array()) {
        const auto it = subs.find(static_cast<uint32_t>(s.number()));
        if (it == subs.end()) continue;
        --subscriber_count_[it->second];
        subs.erase(it);
      }
    } else {
      ++protocol_errors_;
      SendStatus(client, 1, "operation '" + op + "' is not supported by this server");
    }
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    ++protocol_errors_;
    SendStatus(client, 2, std::string("malformed request: ") + e.what());
  }
}

bool FoxgloveServer::HasSubscribers(uint32_t channel) const {
  std::lock_guard lock(mutex_);
  const auto it = subscriber_count_.find(channel);
  return it != subscriber_count_.end() && it->second > 0;
}

std::string FoxgloveServer::MessageFrame(uint32_t sub, Timestamp time, std::span<const uint8_t> payload) {
  std::string frame(1 + 4 + 8 + payload.size(), '\0');
  frame[0] = 0x01;
  for (int i = 0; i < 4; ++i) frame[static_cast<size_t>(1 + i)] = static_cast<char>((sub >> (8 * i)) & 0xFF);
  const auto t = static_cast<uint64_t>(time.nanoseconds());
  for (int i = 0; i < 8; ++i) frame[static_cast<size_t>(5 + i)] = static_cast<char>((t >> (8 * i)) & 0xFF);
  std::copy(payload.begin(), payload.end(), frame.begin() + 13);
  return frame;
}

void FoxgloveServer::SetLatched(uint32_t channel, size_t depth) {
  std::lock_guard lock(mutex_);
  latched_[channel].depth = depth;
}

void FoxgloveServer::Publish(uint32_t channel, Timestamp time, std::span<const uint8_t> payload) {
  std::vector<std::pair<uint64_t, uint32_t>> targets;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [client, subs] : subscriptions_) {
      for (const auto& [sub, ch] : subs) {
        if (ch == channel) targets.emplace_back(client, sub);
      }
    }
    if (const auto l = latched_.find(channel); l != latched_.end() && l->second.depth > 0) {
      l->second.messages.emplace_back(time, std::string(payload.begin(), payload.end()));
      while (l->second.messages.size() > l->second.depth) l->second.messages.pop_front();
    }
  }
  for (const auto& [client, sub] : targets) server_.SendBinary(client, MessageFrame(sub, time, payload));
}

uint64_t FoxgloveServer::protocol_errors() const {
  std::lock_guard lock(mutex_);
  return protocol_errors_;
}

}  // namespace cairn
