#include "daemon/systemd_notifier.h"

#include <systemd/sd-daemon.h>

#include <cstdlib>

namespace cairn {

SystemdNotifier::SystemdNotifier() {
  active_ = std::getenv("NOTIFY_SOCKET") != nullptr;
  uint64_t usec = 0;
  if (active_ && sd_watchdog_enabled(0, &usec) > 0 && usec > 0) {
    watchdog_period_ = std::chrono::microseconds(usec / 2);
  }
}

void SystemdNotifier::Ready(const std::string& status) {
  if (active_) sd_notifyf(0, "READY=1\nSTATUS=%s", status.c_str());
}

void SystemdNotifier::Status(const std::string& status) {
  if (active_) sd_notifyf(0, "STATUS=%s", status.c_str());
}

void SystemdNotifier::Stopping() {
  if (active_) sd_notify(0, "STOPPING=1");
}

void SystemdNotifier::KeepAlive() {
  if (!active_ || watchdog_period_.count() == 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ping_ >= watchdog_period_) {
    sd_notify(0, "WATCHDOG=1");
    last_ping_ = now;
  }
}

}  // namespace cairn
