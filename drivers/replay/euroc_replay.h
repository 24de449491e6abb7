#pragma once
// Replays an EuRoC/ASL dataset as if its sensors were live: IMU samples and stereo pairs are
// published in timestamp order (IMU first on ties, so the filter has propagated to an image's time
// before the image arrives), paced in real time, scaled, or as fast as the pipeline takes them.

#include <atomic>
#include <thread>

#include "drivers/replay/euroc_dataset.h"
#include "drivers/replay/replay_clock.h"
#include "drivers/replay/replay_options.h"
#include "hal/sensor_source_interface.h"

namespace cairn {

class EurocReplay final : public SensorSourceInterface {
 public:
  EurocReplay(EurocDataset dataset, ReplayOptions options);
  ~EurocReplay() override;

  std::string name() const override { return "replay"; }
  Status Start(SensorSink* sink) override;
  void Stop() override;
  bool finished() const override { return finished_.load(std::memory_order_acquire); }

  const EurocDataset& dataset() const { return dataset_; }
  // Published so far (for progress reports).
  size_t published_imu() const { return published_imu_.load(std::memory_order_relaxed); }
  size_t published_stereo() const { return published_stereo_.load(std::memory_order_relaxed); }

 private:
  void Run(std::stop_token stop);
  bool PublishStereo(const EurocStereoEntry& entry, uint64_t counter);

  EurocDataset dataset_;
  ReplayOptions options_;
  SensorSink* sink_ = nullptr;
  ReplayClock clock_;
  std::jthread thread_;
  std::atomic<bool> finished_{false};
  std::atomic<size_t> published_imu_{0};
  std::atomic<size_t> published_stereo_{0};
};

}  // namespace cairn
