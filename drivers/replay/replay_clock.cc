#include "drivers/replay/replay_clock.h"

namespace cairn {

void ReplayClock::Start(Timestamp data_start) {
  data_start_ = data_start;
  wall_start_ = std::chrono::steady_clock::now();
}

bool ReplayClock::WaitUntilDue(std::stop_token& stop, Timestamp t) {
  if (stop.stop_requested()) return false;
  if (options_.pacing == ReplayPacing::kFastAsPossible) return true;
  const double speed = options_.pacing == ReplayPacing::kScaled ? options_.speed : 1.0;
  const auto due = wall_start_ + std::chrono::nanoseconds(static_cast<int64_t>(
                                     static_cast<double>((t - data_start_).nanoseconds()) / speed));
  std::unique_lock lock(mutex_);
  cv_.wait_until(lock, stop, due, [] { return false; });
  return !stop.stop_requested();
}

}  // namespace cairn
