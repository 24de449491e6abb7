#pragma once
// The daemon's data path: the SensorSink that every source publishes into, the bounded queues,
// and the stage loops running on their executors. In live operation a publisher never waits (a
// full queue drops and counts); in deterministic replay every sample is consumed by its stage
// before the publisher returns, so a run's results do not depend on thread timing.

#include <array>
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "daemon/executor.h"
#include "daemon/executor_options.h"
#include "daemon/latency_histogram.h"
#include "daemon/telemetry_stage.h"
#include "daemon/sensor_stream_stats.h"
#include "daemon/spsc_queue.h"
#include "hal/sensor_sink.h"

namespace cairn {

struct PipelineRates {
  double imu_hz = 0.0;      // nominal rates for gap detection; 0 disables it
  double camera_hz = 0.0;
  double wheel_hz = 0.0;
};

struct QueueReport {
  std::string name;
  size_t capacity = 0;
  uint64_t pushed = 0;
  uint64_t dropped = 0;
  uint64_t high_water = 0;
};

struct FaultReport {
  std::map<std::string, std::map<std::string, uint64_t>> counts;  // device -> kind -> count
  uint64_t total = 0;
  std::vector<std::string> first_messages;                         // the first few, verbatim
};

// Time from publication to consumption by the stage, on the monotonic wall clock.
struct LatencyReport {
  std::string name;
  uint64_t count = 0;
  double p50 = 0.0, p99 = 0.0, max = 0.0;  // s
};

struct StereoStageReport {
  uint64_t frame_counter_gaps = 0;  // frames the device numbered but we never saw
  int width = 0;
  int height = 0;
  uint64_t size_changes = 0;
};

class Pipeline final : public SensorSink {
 public:
  Pipeline(const ExecutorsOptions& executors, const QueueOptions& queues, PipelineRates rates,
           bool deterministic);
  ~Pipeline() override;

  // Hands every consumed sample on to `telemetry` (which must outlive the pipeline's threads).
  // Call before Start().
  void SetTelemetry(TelemetryStage* telemetry) { telemetry_ = telemetry; }
  // Starts the stage threads.
  void Start();
  // Lets the stages consume what is queued, then joins them. Publishing must have stopped.
  void StopAndDrain();

  void OnImu(const ImuSample& sample) override;
  void OnStereo(const StereoFrame& frame) override;
  void OnWheelOdometry(const WheelOdometrySample& sample) override;
  void OnTrigger(const TriggerEvent& event) override;
  void OnDeviceFault(const DeviceFault& fault) override;

  // Valid after StopAndDrain().
  const SensorStreamStats& imu_stats() const { return imu_stats_; }
  const SensorStreamStats& stereo_stats() const { return stereo_stats_; }
  const SensorStreamStats& wheel_stats() const { return wheel_stats_; }
  const SensorStreamStats& trigger_stats() const { return trigger_stats_; }
  const StereoStageReport& stereo_report() const { return stereo_report_; }
  std::vector<QueueReport> queue_reports() const;
  std::vector<ExecutorReport> executor_reports() const;
  std::vector<LatencyReport> latency_reports() const;
  FaultReport fault_report() const;

  // Live progress (any thread).
  uint64_t consumed_imu() const { return imu_queue_.popped(); }
  uint64_t consumed_stereo() const { return stereo_queue_.popped(); }
  uint64_t total_dropped() const;
  // IMU samples the estimation thread consumed later than one IMU period after publication.
  uint64_t deadline_misses() const { return deadline_misses_.load(std::memory_order_relaxed); }

 private:
  template <class T>
  struct Queued {
    int64_t enqueued_ns = 0;  // CLOCK_MONOTONIC
    T value{};
  };
  template <class T>
  void Publish(SpscQueue<Queued<T>>& queue, const T& item, WorkSignal& signal);
  void EstimationLoop(std::stop_token stop);
  void StereoLoop(std::stop_token stop);

  const bool deterministic_;
  WorkSignal estimation_signal_;
  WorkSignal stereo_signal_;
  WorkSignal consumed_signal_;  // deterministic mode: the publisher waits on this
  SpscQueue<Queued<ImuSample>> imu_queue_;
  SpscQueue<Queued<WheelOdometrySample>> wheel_queue_;
  SpscQueue<Queued<TriggerEvent>> trigger_queue_;
  SpscQueue<Queued<StereoFrame>> stereo_queue_;
  const Duration imu_deadline_;
  std::atomic<uint64_t> deadline_misses_{0};

  Executor estimation_;
  Executor stereo_;

  // Owned by the estimation thread until joined.
  SensorStreamStats imu_stats_;
  SensorStreamStats wheel_stats_;
  SensorStreamStats trigger_stats_;
  LatencyHistogram imu_latency_, wheel_latency_;
  // Owned by the stereo thread until joined.
  LatencyHistogram stereo_latency_;
  SensorStreamStats stereo_stats_;
  StereoStageReport stereo_report_;
  uint64_t last_frame_counter_ = 0;

  TelemetryStage* telemetry_ = nullptr;
  mutable std::mutex fault_mutex_;
  FaultReport faults_;
  bool started_ = false;
};

}  // namespace cairn
