#pragma once
// Paces a replay: maps recorded time to wall time for real-time or scaled playback, and returns at
// once for as-fast-as-possible playback. Wakes early when the replay is stopped.

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stop_token>

#include "common/timestamp.h"
#include "drivers/replay/replay_options.h"

namespace cairn {

class ReplayClock {
 public:
  explicit ReplayClock(const ReplayOptions& options) : options_(options) {}

  // The first sample's time; playback starts now.
  void Start(Timestamp data_start);
  // Sleeps until `t` is due; false when stopped meanwhile.
  bool WaitUntilDue(std::stop_token& stop, Timestamp t);
  // Wakes a waiting WaitUntilDue (after a stop request).
  void Interrupt() { cv_.notify_all(); }

 private:
  ReplayOptions options_;
  std::chrono::steady_clock::time_point wall_start_;
  Timestamp data_start_;
  std::mutex mutex_;
  std::condition_variable_any cv_;
};

}  // namespace cairn
