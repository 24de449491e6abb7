#pragma once
// sd_notify when running under systemd (Type=notify): READY, STATUS, WATCHDOG keep-alives at half
// the watchdog interval, STOPPING. Outside systemd every call is a no-op.

#include <chrono>
#include <string>

namespace cairn {

class SystemdNotifier {
 public:
  SystemdNotifier();

  bool active() const { return active_; }
  void Ready(const std::string& status);
  void Status(const std::string& status);
  void Stopping();
  // Sends WATCHDOG=1 when due; call from the main loop at least every 100 ms.
  void KeepAlive();

 private:
  bool active_ = false;
  std::chrono::steady_clock::duration watchdog_period_{};
  std::chrono::steady_clock::time_point last_ping_{};
};

}  // namespace cairn
