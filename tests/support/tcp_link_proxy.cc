#include "tests/support/tcp_link_proxy.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <deque>
#include <memory>
#include <string>
#include <vector>

namespace cairn::testing {

sockaddr_in LoopbackAddress(int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return a;
}

namespace {

using Clock = std::chrono::steady_clock;

void NonBlocking(int fd) {
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
  const int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

struct Chunk {
  Clock::time_point due;
  std::string bytes;
  size_t written = 0;
};

// One proxied connection: bytes read from one end wait their delay, then go to the other.
struct Pipe {
  int fd[2] = {-1, -1};  // the client's end, the target's
  std::deque<Chunk> to[2];  // waiting to be written to fd[i]
  bool open = true;

  ~Pipe() {
    for (int f : fd) {
      if (f >= 0) close(f);
    }
  }
};

}  // namespace

TcpLinkProxy::TcpLinkProxy(int listen_port, int target_port, std::chrono::milliseconds one_way_delay)
    : target_port_(target_port), delay_(one_way_delay) {
  listen_fd_ = socket(AF_INET, SOCK_STREAM, 0);
  const int one = 1;
  setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  const sockaddr_in a = LoopbackAddress(listen_port);
  if (bind(listen_fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0 || listen(listen_fd_, 16) != 0) {
    close(listen_fd_);
    listen_fd_ = -1;
    return;
  }
  NonBlocking(listen_fd_);
  thread_ = std::jthread([this](std::stop_token stop) { Loop(stop); });
}

TcpLinkProxy::~TcpLinkProxy() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
  if (listen_fd_ >= 0) close(listen_fd_);
}

void TcpLinkProxy::Loop(std::stop_token stop) {
  std::vector<std::unique_ptr<Pipe>> pipes;
  std::vector<char> buffer(1 << 16);
  while (!stop.stop_requested()) {
    const bool cut = cut_.load();
    if (cut) pipes.clear();  // the outage drops every connection with what it carried
    std::vector<pollfd> fds{{listen_fd_, POLLIN, 0}};
    const auto wait = std::chrono::milliseconds(10);
    const Clock::time_point now = Clock::now();
    for (const auto& p : pipes) {
      for (int i = 0; i < 2; ++i) {
        short events = POLLIN;
        if (!p->to[i].empty() && p->to[i].front().due <= now) events |= POLLOUT;
        fds.push_back(pollfd{p->fd[i], events, 0});
      }
    }
    poll(fds.data(), fds.size(), static_cast<int>(wait.count()));
    const size_t polled = pipes.size();  // a connection accepted below has no poll result yet
    if (fds[0].revents & POLLIN) {
      const int client = accept(listen_fd_, nullptr, nullptr);
      if (client >= 0) {
        auto p = std::make_unique<Pipe>();
        p->fd[0] = client;
        p->fd[1] = socket(AF_INET, SOCK_STREAM, 0);
        const sockaddr_in a = LoopbackAddress(target_port_);
        if (!cut_.load() && connect(p->fd[1], reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0) {
          NonBlocking(p->fd[0]);
          NonBlocking(p->fd[1]);
          pipes.push_back(std::move(p));
          ++connections_;
        }  // else closed at once: the link is down or the far end is not up
      }
    }
    const Clock::time_point after = Clock::now();
    for (size_t k = 0; k < pipes.size(); ++k) {
      Pipe& p = *pipes[k];
      for (int i = 0; i < 2 && p.open; ++i) {
        const short revents = k < polled ? fds[1 + 2 * k + static_cast<size_t>(i)].revents : 0;
        if (revents & (POLLIN | POLLHUP | POLLERR)) {
          const ssize_t n = read(p.fd[i], buffer.data(), buffer.size());
          if (n > 0) {
            p.to[1 - i].push_back(Chunk{after + delay_, std::string(buffer.data(), static_cast<size_t>(n)), 0});
          } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
            p.open = false;  // either end gone: the connection drops, as a radio link's would
          }
        }
        while (p.open && !p.to[i].empty() && p.to[i].front().due <= after) {
          Chunk& c = p.to[i].front();
          const ssize_t n = write(p.fd[i], c.bytes.data() + c.written, c.bytes.size() - c.written);
          if (n < 0) {
            if (errno != EAGAIN && errno != EINTR) p.open = false;
            break;
          }
          c.written += static_cast<size_t>(n);
          forwarded_ += static_cast<uint64_t>(n);
          if (c.written < c.bytes.size()) break;
          p.to[i].pop_front();
        }
      }
    }
    std::erase_if(pipes, [](const std::unique_ptr<Pipe>& p) { return !p->open; });
  }
}

}  // namespace cairn::testing
