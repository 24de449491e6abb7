#pragma once
// A small WebSocket server on websocketpp + standalone asio, running on its own thread. Each client
// has a bounded send queue: when a client reads too slowly its oldest queued messages are dropped
// (and counted), so a slow or stalled viewer never holds back the daemon or the other viewers.
//
// This header (and its .cc) stays within C++17: Debian's websocketpp 0.8 does not compile as C++20.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace cairn {

class WebSocketServer {
 public:
  struct Callbacks {
    std::function<void(uint64_t client)> on_open;
    std::function<void(uint64_t client)> on_close;
    std::function<void(uint64_t client, const std::string& text)> on_text;
  };

  WebSocketServer();
  ~WebSocketServer();
  WebSocketServer(const WebSocketServer&) = delete;
  WebSocketServer& operator=(const WebSocketServer&) = delete;

  // Listens on address:port (port 0 picks a free one) and accepts only clients that offer
  // `subprotocol`. `max_queued` bounds each client's send queue in messages.
  bool Start(const std::string& address, uint16_t port, const std::string& subprotocol,
             size_t max_queued, Callbacks callbacks, std::string* error);
  void Stop();
  uint16_t port() const;

  // Thread safe; never blocks on the network.
  void SendText(uint64_t client, std::string text);
  void SendBinary(uint64_t client, std::string bytes);
  // Closes one client's connection (e.g. after a protocol error).
  void Close(uint64_t client, const std::string& reason);

  uint64_t dropped_messages() const;
  // CPU time of the server thread, known once Stop() has returned.
  double cpu_seconds() const;
  size_t client_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cairn
