#pragma once
// The team's messages over ZeroMQ, authenticated and encrypted with CURVE. Each robot binds one
// ROUTER as a CURVE server and connects one DEALER per teammate as a CURVE client: A's messages
// to B travel A's DEALER -> B's ROUTER. A ZAP handler admits only the team file's public keys and
// names the sender by its key, never by what the sender says; a client only talks to the server
// key the team file lists, so a robot with an unlisted key can neither send nor be sent to. No
// broker: any robot may be missing, sockets reconnect on their own.
//
// Send() and Receive() belong to one thread (the comms executor); counters() to any.

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "common/status.h"
#include "common/timestamp.h"
#include "daemon/comms/curve_keys.h"
#include "daemon/comms/zmq_transport_options.h"

namespace cairn {

struct ZmqPeer {
  std::string name;
  std::string endpoint;    // tcp://host:port
  std::string public_key;  // Z85
};

struct ZmqMessage {
  std::string peer;  // the sender's team name, from its key
  std::string bytes;
};

struct ZmqTransportCounters {
  uint64_t sent_messages = 0;
  uint64_t sent_bytes = 0;
  uint64_t send_queue_full = 0;       // sends refused: the peer's queue full or no connection
  uint64_t received_messages = 0;
  uint64_t received_bytes = 0;
  uint64_t refused_unknown_key = 0;   // CURVE handshakes of keys not in the team file
  uint64_t refused_malformed = 0;     // messages not of one data frame
  uint64_t handshake_failures = 0;    // not counted by this transport (no socket monitor)
  std::map<std::string, uint64_t> sent_bytes_by_peer;
  std::map<std::string, uint64_t> received_bytes_by_peer;
};

class ZmqTransport {
 public:
  static Expected<std::unique_ptr<ZmqTransport>> Create(const ZmqTransportOptions& options, const CurveKeyPair& keys,
                                                        const std::vector<ZmqPeer>& peers);
  ~ZmqTransport();
  ZmqTransport(const ZmqTransport&) = delete;
  ZmqTransport& operator=(const ZmqTransport&) = delete;

  // Never blocks: NotFound for a stranger, Unavailable when the peer is not connected or its
  // queue is full.
  Status Send(const std::string& peer, const std::string& bytes);
  // The next message, waiting at most `timeout` (zero: only what is there).
  std::optional<ZmqMessage> Receive(Duration timeout);
  ZmqTransportCounters counters() const;
  const std::string& bound_endpoint() const { return bound_endpoint_; }

 private:
  ZmqTransport() = default;
  Status Open(const ZmqTransportOptions& options, const CurveKeyPair& keys, const std::vector<ZmqPeer>& peers);
  void ServeZap();

  void* context_ = nullptr;
  void* router_ = nullptr;
  void* zap_ = nullptr;  // used by zap_thread_ only once it runs
  std::map<std::string, void*> dealers_;
  std::map<std::string, std::string> names_by_key_;  // 32-byte key -> team name
  std::thread zap_thread_;
  std::string bound_endpoint_;

  mutable std::mutex counters_mutex_;
  ZmqTransportCounters counters_;
};

}  // namespace cairn
