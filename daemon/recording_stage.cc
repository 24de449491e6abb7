#include "daemon/recording_stage.h"

#include <spdlog/spdlog.h>

#include <limits>

namespace cairn {

RecordingStage::RecordingStage(std::string directory, const RecordingOptions& options,
                               const ExecutorOptions& executor, bool deterministic)
    : deterministic_(deterministic),
      imu_(static_cast<size_t>(options.queue_depth) * 8),  // IMU samples are small and frequent
      wheel_(static_cast<size_t>(options.queue_depth)),
      stereo_(static_cast<size_t>(options.queue_depth)),
      recorder_(std::move(directory), options),
      executor_("telemetry", executor) {}

RecordingStage::~RecordingStage() { StopAndDrain(); }

void RecordingStage::Start() {
  if (started_) return;
  started_ = true;
  executor_.Start([this](std::stop_token stop) { Loop(stop); });
}

void RecordingStage::StopAndDrain() {
  if (!started_) return;
  executor_.RequestStop();
  work_.Notify();
  executor_.Join();
  started_ = false;
  if (Status s = recorder_.Close(); !s.ok()) spdlog::error("recording: {}", s.ToString());
}

template <class T>
void RecordingStage::Offer(SpscQueue<Item<T>>& queue, const T& value) {
  const Item<T> item{next_sequence_.fetch_add(1, std::memory_order_relaxed), value};
  if (deterministic_) {
    while (true) {
      const uint32_t seen = space_.sequence();
      if (queue.size() < queue.capacity() && queue.TryPush(item)) break;
      space_.WaitChange(seen);
    }
  } else {
    queue.TryPush(item);
  }
  work_.Notify();
}

void RecordingStage::OfferImu(const ImuSample& s) { Offer(imu_, s); }
void RecordingStage::OfferWheelOdometry(const WheelOdometrySample& s) { Offer(wheel_, s); }
void RecordingStage::OfferStereo(const StereoFrame& f) { Offer(stereo_, f); }

void RecordingStage::Loop(std::stop_token stop) {
  std::stop_callback wake(stop, [this] { work_.Notify(); });
  constexpr uint64_t kNone = std::numeric_limits<uint64_t>::max();
  while (true) {
    const uint32_t seen = work_.sequence();
    bool worked = false;
    while (true) {
      const auto* i = imu_.Front();
      const auto* w = wheel_.Front();
      const auto* s = stereo_.Front();
      const uint64_t si = i ? i->sequence : kNone, sw = w ? w->sequence : kNone, ss = s ? s->sequence : kNone;
      if (si == kNone && sw == kNone && ss == kNone) break;
      Status status;
      if (si <= sw && si <= ss) {
        status = recorder_.RecordImu(i->value);
        imu_.PopFront();
      } else if (sw <= ss) {
        status = recorder_.RecordWheelOdometry(w->value);
        wheel_.PopFront();
      } else {
        status = recorder_.RecordStereo(s->value);
        stereo_.PopFront();
      }
      if (!status.ok() && !error_logged_) {
        // A full disk must not stop the robot: log once, count the rest in the report.
        spdlog::error("recording: {} (further errors are only counted)", status.ToString());
        error_logged_ = true;
      }
      worked = true;
      space_.Notify();
    }
    if (stop.stop_requested() && imu_.empty() && wheel_.empty() && stereo_.empty()) return;
    if (!worked) work_.WaitChange(seen);
  }
}

}  // namespace cairn
