// cairnd speaks the sd_notify protocol when systemd starts it (Type=notify): READY, STATUS,
// WATCHDOG keep-alives at half the watchdog interval, STOPPING. A datagram socket stands in for
// systemd's notification socket.

#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <poll.h>

#include <atomic>
#include <filesystem>
#include <thread>

#include <gtest/gtest.h>

#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

TEST(CairndSystemdNotifyTest, ReadyStatusWatchdogStopping) {
  if (!std::filesystem::exists(testing::EurocMicro())) GTEST_SKIP() << "missing " << testing::EurocMicro();
  const testing::ScopedTempDir temp("notify");
  const std::string dir = temp.path();
  const std::string path = dir + "/notify.sock";
  const int fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::snprintf(addr.sun_path, sizeof(addr.sun_path), "%s", path.c_str());
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0);

  // Like systemd, read as messages arrive: a unix datagram queue holds only a few, and a full one
  // blocks the sender.
  std::vector<std::string> messages;
  std::atomic<bool> stop{false};
  std::thread reader([&] {
    char buf[4096];
    while (!stop.load()) {
      pollfd p{fd, POLLIN, 0};
      if (poll(&p, 1, 20) <= 0) continue;
      for (ssize_t n; (n = recv(fd, buf, sizeof(buf), 0)) > 0;) messages.emplace_back(buf, static_cast<size_t>(n));
    }
  });

  testing::ProcessOptions po;
  po.env = {"NOTIFY_SOCKET=" + path, "WATCHDOG_USEC=200000"};
  po.signal = SIGTERM;
  po.signal_when_output_contains = "running";
  po.signal_after = std::chrono::milliseconds(1200);
  const auto r = testing::RunProcess(
      {testing::BinaryDir() + "/daemon/cairnd", "--config", testing::SourceDir() + "/configs/euroc.yaml",
       "--replay", testing::EurocMicro(), "--out", dir + "/out", "--set", "replay.pacing=realtime",
       "--set", "daemon.status_interval=0.2"},
      po);
  stop.store(true);
  reader.join();
  close(fd);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_FALSE(messages.empty());
  EXPECT_EQ(messages.front().rfind("READY=1", 0), 0u) << messages.front();
  EXPECT_EQ(messages.back(), "STOPPING=1");
  int watchdog = 0, status = 0;
  for (const auto& m : messages) {
    watchdog += m == "WATCHDOG=1";
    status += m.rfind("STATUS=imu ", 0) == 0;
  }
  // About 1.2 s with a 0.1 s ping period and a 0.2 s status period; generous lower bounds keep
  // this independent of machine load while still failing if the pings stop.
  EXPECT_GE(watchdog, 3);
  EXPECT_GE(status, 2);
}

}  // namespace
}  // namespace cairn
