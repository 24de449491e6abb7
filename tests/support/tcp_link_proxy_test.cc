#include "tests/support/tcp_link_proxy.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace cairn::testing {
namespace {

using Clock = std::chrono::steady_clock;

int Listen(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  const int one = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  const sockaddr_in a = LoopbackAddress(port);
  if (bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0 || listen(fd, 4) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

int Connect(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  const sockaddr_in a = LoopbackAddress(port);
  if (connect(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

// Reads `n` bytes within `timeout_ms`, or what came until then.
std::string ReadSome(int fd, size_t n, int timeout_ms) {
  std::string out;
  const auto end = Clock::now() + std::chrono::milliseconds(timeout_ms);
  while (out.size() < n && Clock::now() < end) {
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, 20) <= 0) continue;
    char b[4096];
    const ssize_t k = read(fd, b, sizeof b);
    if (k <= 0) break;
    out.append(b, static_cast<size_t>(k));
  }
  return out;
}

// The proxy counts a chunk after write() returns, so the far end may hold the bytes a moment
// before the count does.
uint64_t ForwardedAfterSettling(const TcpLinkProxy& proxy, uint64_t expected) {
  const auto end = Clock::now() + std::chrono::seconds(2);
  while (proxy.forwarded_bytes() < expected && Clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return proxy.forwarded_bytes();
}

int BasePort() { return 40000 + static_cast<int>(getpid() % 4000) * 4; }

TEST(TcpLinkProxyTest, BytesArriveBothWaysAfterTheDelay) {
  const int target = BasePort(), through = BasePort() + 1;
  const int server = Listen(target);
  ASSERT_GE(server, 0);
  TcpLinkProxy proxy(through, target, std::chrono::milliseconds(300));
  ASSERT_TRUE(proxy.listening());
  const int client = Connect(through);
  ASSERT_GE(client, 0);
  const int accepted = accept(server, nullptr, nullptr);
  ASSERT_GE(accepted, 0);
  const auto sent = Clock::now();
  ASSERT_EQ(write(client, "hello", 5), 5);
  EXPECT_EQ(ReadSome(accepted, 5, 2000), "hello");
  EXPECT_GE(Clock::now() - sent, std::chrono::milliseconds(300));
  ASSERT_EQ(write(accepted, "back", 4), 4);
  EXPECT_EQ(ReadSome(client, 4, 2000), "back");
  EXPECT_EQ(ForwardedAfterSettling(proxy, 9), 9u);
  close(client);
  close(accepted);
  close(server);
}

TEST(TcpLinkProxyTest, AnOutageDropsTheConnectionAndRefusesNewOnesUntilItHeals) {
  const int target = BasePort() + 2, through = BasePort() + 3;
  const int server = Listen(target);
  ASSERT_GE(server, 0);
  TcpLinkProxy proxy(through, target, std::chrono::milliseconds(0));
  const int client = Connect(through);
  ASSERT_GE(client, 0);
  const int accepted = accept(server, nullptr, nullptr);
  ASSERT_GE(accepted, 0);
  proxy.SetCut(true);
  EXPECT_EQ(ReadSome(client, 1, 1000), "");  // closed: read returns 0
  const int during = Connect(through);  // accepted by the kernel, closed by the proxy
  ASSERT_GE(during, 0);
  EXPECT_EQ(ReadSome(during, 1, 500), "");
  proxy.SetCut(false);
  const int after = Connect(through);
  ASSERT_GE(after, 0);
  ASSERT_EQ(write(after, "x", 1), 1);
  const int accepted_after = accept(server, nullptr, nullptr);
  ASSERT_GE(accepted_after, 0);
  EXPECT_EQ(ReadSome(accepted_after, 1, 1000), "x");
  EXPECT_EQ(proxy.connections(), 2u);
  for (int fd : {client, accepted, during, after, accepted_after, server}) close(fd);
}

}  // namespace
}  // namespace cairn::testing
