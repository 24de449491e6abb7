#pragma once

#include <string>

#include "common/options_visitor.h"
#include "daemon/telemetry/image_encoding_options.h"

namespace cairn {

// The live Foxglove WebSocket stream (protocol foxglove.websocket.v1). Loopback by default: a
// robot's stream reaches the ground only through a deliberate address (or an SSH tunnel).
struct LiveStreamOptions {
  bool enabled = false;
  std::string address = "127.0.0.1";
  int64_t port = 8765;        // 0 picks a free port (logged at start-up)
  int64_t image_every = 5;    // send every Nth stereo frame's images
  ImageEncodingOptions images;
  int64_t client_queue = 256; // messages queued per client before the oldest are dropped

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Text("address", address);
    v.Integer("port", port, 0, 65535, "");
    v.Integer("image_every", image_every, 1, 1000, "frames");
    v.Section("images", images);
    v.Integer("client_queue", client_queue, 1, 1 << 20, "messages");
  }
};

}  // namespace cairn
