#pragma once
// One direction of a radio link between two processes for integration tests, in user space since
// `tc netem` is missing here: a TCP proxy that accepts on one loopback port, connects to another,
// and forwards bytes both ways after a fixed one-way delay. `SetCut(true)` is an outage: every
// connection through it drops with its bytes in flight, and new ones are closed until it heals.
// Packet loss is not emulated here (a TCP stream cannot lose bytes): drop the proxy's packets with
// nftables for that.

#include <netinet/in.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

namespace cairn::testing {

sockaddr_in LoopbackAddress(int port);  // 127.0.0.1:port

class TcpLinkProxy {
 public:
  // Listens on 127.0.0.1:`listen_port` at once; fails the calling test when it cannot.
  TcpLinkProxy(int listen_port, int target_port, std::chrono::milliseconds one_way_delay);
  ~TcpLinkProxy();
  TcpLinkProxy(const TcpLinkProxy&) = delete;
  TcpLinkProxy& operator=(const TcpLinkProxy&) = delete;

  bool listening() const { return listen_fd_ >= 0; }
  void SetCut(bool cut) { cut_.store(cut); }
  uint64_t forwarded_bytes() const { return forwarded_.load(); }
  uint64_t connections() const { return connections_.load(); }

 private:
  void Loop(std::stop_token stop);

  int listen_fd_ = -1;
  int target_port_;
  std::chrono::milliseconds delay_;
  std::atomic<bool> cut_{false};
  std::atomic<uint64_t> forwarded_{0};
  std::atomic<uint64_t> connections_{0};
  std::jthread thread_;
};

}  // namespace cairn::testing
