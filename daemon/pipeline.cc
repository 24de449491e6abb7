#include "daemon/pipeline.h"

#include "hal/monotonic_clock.h"

#include <spdlog/spdlog.h>

#include <thread>

namespace cairn {
namespace {

int64_t MonotonicNs() { return MonotonicClock().Now().nanoseconds(); }

}  // namespace

Pipeline::Pipeline(const ExecutorsOptions& executors, const QueueOptions& queues,
                   PipelineRates rates, bool deterministic)
    : deterministic_(deterministic),
      imu_queue_(static_cast<size_t>(queues.imu)),
      wheel_queue_(static_cast<size_t>(queues.wheel_odometry)),
      trigger_queue_(static_cast<size_t>(queues.wheel_odometry)),
      stereo_queue_(static_cast<size_t>(queues.stereo)),
      imu_deadline_(rates.imu_hz > 0.0 ? Duration::Seconds(1.0 / rates.imu_hz) : Duration::Seconds(0.01)),
      estimation_("estimation", executors.estimation),
      stereo_("stereo", executors.stereo),
      imu_stats_(rates.imu_hz),
      wheel_stats_(rates.wheel_hz),
      trigger_stats_(rates.camera_hz),
      stereo_stats_(rates.camera_hz) {}

Pipeline::~Pipeline() { StopAndDrain(); }

void Pipeline::Start() {
  if (started_) return;
  started_ = true;
  estimation_.Start([this](std::stop_token stop) { EstimationLoop(stop); });
  stereo_.Start([this](std::stop_token stop) { StereoLoop(stop); });
}

void Pipeline::StopAndDrain() {
  if (!started_) return;
  estimation_.RequestStop();
  stereo_.RequestStop();
  estimation_signal_.Notify();
  stereo_signal_.Notify();
  estimation_.Join();
  stereo_.Join();
  started_ = false;
}

template <class T>
void Pipeline::Publish(SpscQueue<Queued<T>>& queue, const T& value, WorkSignal& signal) {
  const Queued<T> item{MonotonicNs(), value};
  if (!deterministic_) {
    if (queue.TryPush(item)) signal.Notify();
    return;
  }
  // Deterministic: enqueue, then wait until the stage has consumed this very item.
  const uint64_t target = queue.pushed() + 1;
  while (!queue.TryPush(item)) std::this_thread::yield();
  signal.Notify();
  while (true) {
    const uint32_t seen = consumed_signal_.sequence();
    if (queue.popped() >= target) break;
    consumed_signal_.WaitChange(seen);
  }
}

void Pipeline::OnImu(const ImuSample& s) { Publish(imu_queue_, s, estimation_signal_); }
void Pipeline::OnWheelOdometry(const WheelOdometrySample& s) { Publish(wheel_queue_, s, estimation_signal_); }
void Pipeline::OnTrigger(const TriggerEvent& e) { Publish(trigger_queue_, e, estimation_signal_); }
void Pipeline::OnStereo(const StereoFrame& f) { Publish(stereo_queue_, f, stereo_signal_); }

void Pipeline::OnDeviceFault(const DeviceFault& fault) {
  // Faults are rare and come from driver threads: a lock here never touches a real-time path.
  {
    std::lock_guard lock(fault_mutex_);
    ++faults_.counts[fault.device][DeviceFaultKindName(fault.kind)];
    ++faults_.total;
    if (faults_.first_messages.size() < 20) {
      faults_.first_messages.push_back(fault.device + ": " + DeviceFaultKindName(fault.kind) +
                                       ": " + fault.detail);
    }
  }
  spdlog::warn("device fault: {}: {}: {}", fault.device, DeviceFaultKindName(fault.kind), fault.detail);
}

void Pipeline::EstimationLoop(std::stop_token stop) {
  std::stop_callback wake(stop, [this] { estimation_signal_.Notify(); });
  while (true) {
    const uint32_t seen = estimation_signal_.sequence();
    bool worked = false;
    // Consume the three inputs in timestamp order.
    while (true) {
      const auto* imu = imu_queue_.Front();
      const auto* wheel = wheel_queue_.Front();
      const auto* trig = trigger_queue_.Front();
      if (imu == nullptr && wheel == nullptr && trig == nullptr) break;
      const Timestamp ti = imu ? imu->value.time : Timestamp::Max();
      const Timestamp tw = wheel ? wheel->value.time : Timestamp::Max();
      const Timestamp tt = trig ? trig->value.time : Timestamp::Max();
      const int64_t now = MonotonicNs();
      if (imu != nullptr && ti <= tw && ti <= tt) {
        const Duration latency = Duration::Nanoseconds(now - imu->enqueued_ns);
        imu_latency_.Record(latency);
        if (latency > imu_deadline_) deadline_misses_.fetch_add(1, std::memory_order_relaxed);
        imu_stats_.Add(ti);
        if (telemetry_ != nullptr) telemetry_->OfferImu(imu->value);
        imu_queue_.PopFront();
      } else if (wheel != nullptr && tw <= tt) {
        wheel_latency_.Record(Duration::Nanoseconds(now - wheel->enqueued_ns));
        wheel_stats_.Add(tw);
        if (telemetry_ != nullptr) telemetry_->OfferWheelOdometry(wheel->value);
        wheel_queue_.PopFront();
      } else {
        trigger_stats_.Add(tt);
        trigger_queue_.PopFront();
      }
      worked = true;
      if (deterministic_) consumed_signal_.Notify();
    }
    if (stop.stop_requested() && imu_queue_.empty() && wheel_queue_.empty() && trigger_queue_.empty()) {
      return;
    }
    if (!worked) estimation_signal_.WaitChange(seen);
  }
}

void Pipeline::StereoLoop(std::stop_token stop) {
  std::stop_callback wake(stop, [this] { stereo_signal_.Notify(); });
  while (true) {
    const uint32_t seen = stereo_signal_.sequence();
    bool worked = false;
    while (const auto* queued = stereo_queue_.Front()) {
      stereo_latency_.Record(Duration::Nanoseconds(MonotonicNs() - queued->enqueued_ns));
      const StereoFrame* f = &queued->value;
      stereo_stats_.Add(f->time);
      if (stereo_stats_.count() > 1 && f->frame_counter > last_frame_counter_ + 1) {
        stereo_report_.frame_counter_gaps += f->frame_counter - last_frame_counter_ - 1;
      }
      last_frame_counter_ = f->frame_counter;
      if (f->left.width != stereo_report_.width || f->left.height != stereo_report_.height) {
        if (stereo_stats_.count() > 1) ++stereo_report_.size_changes;
        stereo_report_.width = f->left.width;
        stereo_report_.height = f->left.height;
      }
      if (telemetry_ != nullptr) telemetry_->OfferStereo(*f);
      stereo_queue_.PopFront();
      worked = true;
      if (deterministic_) consumed_signal_.Notify();
    }
    if (stop.stop_requested() && stereo_queue_.empty()) return;
    if (!worked) stereo_signal_.WaitChange(seen);
  }
}

std::vector<QueueReport> Pipeline::queue_reports() const {
  const auto r = [](const char* name, const auto& q) {
    return QueueReport{name, q.capacity(), q.pushed(), q.dropped(), q.high_water()};
  };
  return {r("imu", imu_queue_), r("wheel_odometry", wheel_queue_), r("trigger", trigger_queue_),
          r("stereo", stereo_queue_)};
}

uint64_t Pipeline::total_dropped() const {
  return imu_queue_.dropped() + wheel_queue_.dropped() + trigger_queue_.dropped() +
         stereo_queue_.dropped();
}

std::vector<LatencyReport> Pipeline::latency_reports() const {
  const auto r = [](const char* name, const LatencyHistogram& h) {
    return LatencyReport{name, h.count(), h.Quantile(0.5).seconds(), h.Quantile(0.99).seconds(), h.max().seconds()};
  };
  return {r("imu", imu_latency_), r("wheel_odometry", wheel_latency_), r("stereo", stereo_latency_)};
}

std::vector<ExecutorReport> Pipeline::executor_reports() const {
  return {estimation_.report(), stereo_.report()};
}

FaultReport Pipeline::fault_report() const {
  std::lock_guard lock(fault_mutex_);
  return faults_;
}

}  // namespace cairn
