#pragma once
// Foxglove WebSocket protocol v1 on top of WebSocketServer: server info and channel adverts on
// connect, subscribe/unsubscribe, and binary Message Data frames to each subscriber. Publish() is
// safe from any thread and never blocks on the network.

#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"
#include "common/timestamp.h"
#include "daemon/telemetry/websocket_server.h"

namespace cairn {

struct FoxgloveChannel {
  uint32_t id = 0;
  std::string topic;
  std::string encoding;         // "protobuf", "json"
  std::string schema_name;
  std::string schema;           // as sent: base64 FileDescriptorSet for protobuf, text for json
  std::string schema_encoding;  // "protobuf", "jsonschema"
};

class FoxgloveServer {
 public:
  explicit FoxgloveServer(std::string name) : name_(std::move(name)) {}
  ~FoxgloveServer() { Stop(); }

  // Channels must be added before Start().
  uint32_t AddChannel(FoxgloveChannel channel);
  // The channel keeps its last `depth` messages and sends them to each new subscriber first (a
  // viewer that connects late still sees the latest graph, the recent log lines).
  void SetLatched(uint32_t channel, size_t depth);
  Status Start(const std::string& address, uint16_t port, size_t client_queue);
  void Stop();
  uint16_t port() const { return server_.port(); }

  // True when some client subscribes to `channel` (so callers can skip serializing).
  bool HasSubscribers(uint32_t channel) const;
  void Publish(uint32_t channel, Timestamp time, std::span<const uint8_t> payload);

  uint64_t dropped_messages() const { return server_.dropped_messages(); }
  double cpu_seconds() const { return server_.cpu_seconds(); }
  size_t client_count() const { return server_.client_count(); }
  uint64_t protocol_errors() const;

  static std::string Base64(std::span<const uint8_t> bytes);

 private:
  void OnOpen(uint64_t client);
  void OnClose(uint64_t client);
  void OnText(uint64_t client, const std::string& text);
  void SendStatus(uint64_t client, int level, const std::string& message);
  static std::string MessageFrame(uint32_t subscription, Timestamp time, std::span<const uint8_t> payload);

  std::string name_;
  std::vector<FoxgloveChannel> channels_;
  WebSocketServer server_;
  mutable std::mutex mutex_;
  // client -> subscription id -> channel
  std::map<uint64_t, std::map<uint32_t, uint32_t>> subscriptions_;
  std::map<uint32_t, size_t> subscriber_count_;  // channel -> subscriptions
  struct Latched {
    size_t depth = 0;
    std::deque<std::pair<Timestamp, std::string>> messages;
  };
  std::map<uint32_t, Latched> latched_;  // channel -> its last messages
  uint64_t protocol_errors_ = 0;
  bool started_ = false;
};

}  // namespace cairn
