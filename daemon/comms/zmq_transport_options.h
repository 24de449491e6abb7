#pragma once
// The `team.transport` section: how cairnd's ZeroMQ sockets behave on a slow, lossy radio link.

#include <cstdint>
#include <string>

#include "common/options_visitor.h"

namespace cairn {

struct ZmqTransportOptions {
  // Where this robot binds (tcp://host:port): its entry of the team file unless `team.listen`
  // says otherwise; not a key of this section.
  std::string listen;
  // Larger messages drop the sender's connection before they are read into memory.
  int64_t max_message_bytes = 4 << 20;
  // Messages waiting per peer; beyond them a send is refused and the exchange tries again later.
  int64_t send_queue_messages = 16;
  // A link silent this long is taken down and reconnected (heartbeats every interval).
  double heartbeat_interval = 1.0;
  double heartbeat_timeout = 5.0;
  double reconnect_interval = 0.2;
  double reconnect_interval_max = 5.0;

  void Visit(OptionsVisitor& v) {
    v.Integer("max_message_bytes", max_message_bytes, 4096, int64_t{1} << 30, "bytes");
    v.Integer("send_queue_messages", send_queue_messages, 1, 100000, "messages");
    v.Number("heartbeat_interval", heartbeat_interval, 0.05, 600.0, "s");
    v.Number("heartbeat_timeout", heartbeat_timeout, 0.1, 3600.0, "s");
    v.Number("reconnect_interval", reconnect_interval, 0.01, 600.0, "s");
    v.Number("reconnect_interval_max", reconnect_interval_max, 0.01, 3600.0, "s");
  }
  Status Validate() const {
    if (heartbeat_timeout <= heartbeat_interval) {
      return InvalidArgumentError("heartbeat_timeout must exceed heartbeat_interval");
    }
    if (reconnect_interval_max < reconnect_interval) {
      return InvalidArgumentError("reconnect_interval_max must not be below reconnect_interval");
    }
    return Status::Ok();
  }
};

}  // namespace cairn
