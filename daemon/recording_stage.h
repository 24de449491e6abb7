#pragma once
// Runs the MCAP recorder on the telemetry executor. Stages hand over what they consumed through
// bounded queues (allocation and lock free, so the estimation thread may call it); each item
// carries a global sequence number so the file keeps the order in which the pipeline consumed
// samples. Live: a full queue drops and counts. Deterministic replay: the stage waits instead.

#include <atomic>
#include <string>

#include "daemon/executor.h"
#include "daemon/mcap_recorder.h"
#include "daemon/spsc_queue.h"

namespace cairn {

class RecordingStage {
 public:
  RecordingStage(std::string directory, const RecordingOptions& options,
                 const ExecutorOptions& executor, bool deterministic);
  ~RecordingStage();

  void Start();
  // Writes everything queued, closes the file and joins the thread.
  void StopAndDrain();

  void OfferImu(const ImuSample& s);
  void OfferWheelOdometry(const WheelOdometrySample& s);
  void OfferStereo(const StereoFrame& f);

  // Valid after StopAndDrain().
  const RecordingReport& report() const { return recorder_.report(); }
  uint64_t dropped() const { return imu_.dropped() + wheel_.dropped() + stereo_.dropped(); }
  ExecutorReport executor_report() const { return executor_.report(); }

 private:
  template <class T>
  struct Item {
    uint64_t sequence = 0;
    T value{};
  };
  template <class T>
  void Offer(SpscQueue<Item<T>>& queue, const T& value);
  void Loop(std::stop_token stop);

  const bool deterministic_;
  std::atomic<uint64_t> next_sequence_{0};
  WorkSignal work_;
  WorkSignal space_;
  SpscQueue<Item<ImuSample>> imu_;
  SpscQueue<Item<WheelOdometrySample>> wheel_;
  SpscQueue<Item<StereoFrame>> stereo_;
  McapRecorder recorder_;
  Executor executor_;
  bool started_ = false;
  bool error_logged_ = false;
};

}  // namespace cairn
