#pragma once
// Paces a recorded or simulated stream against the wall clock: real time, scaled, or as fast as
// possible. Shared by the EuRoC replay and the simulator source.

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stop_token>

#include "drivers/replay_options.h"
#include "hal/timestamp.h"

namespace cairn {

class ReplayPacer {
 public:
  explicit ReplayPacer(const ReplayOptions& options) : options_(options) {}

  // Data time `data_start` is due now.
  void Start(Timestamp data_start);
  // Sleeps until data time `t` is due; false when `stop` was requested meanwhile.
  bool WaitUntilDue(std::stop_token& stop, Timestamp t);
  // Wakes a sleeping WaitUntilDue so that it sees a stop request at once.
  void Wake() { cv_.notify_all(); }

 private:
  ReplayOptions options_;
  std::mutex mutex_;
  std::condition_variable_any cv_;
  std::chrono::steady_clock::time_point wall_start_;
  Timestamp data_start_;
};

}  // namespace cairn
