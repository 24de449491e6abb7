#pragma once
// Puts the trigger's time on the camera's frames. A SensorSink placed between a hardware-triggered
// stereo camera (and its trigger, gpiod_trigger.h) and the daemon's sink: it keeps the trigger's
// edges, matches every StereoFrame to the edge that started its exposure and forwards the frame
// stamped with that edge's time. Everything else passes through unchanged.
//
// Which instant: StereoFrame::time is the middle of the exposure (hal/stereo_frame.h; the filter
// clones its state there). An edge marks the trigger, and the exposure starts `latency` later
// (the camera's trigger delay), so a matched frame's time is
//   edge + latency + exposure / 2,
// with the exposure the frame reports; a frame that reports none (automatic exposure) is stamped
// at the exposure's start, as the camera drivers stamp it themselves then.
//
// Matching: an edge comes before its frame (a GPIO interrupt against a frame still to be read out
// and transferred), and the frame's own time minus its edge's time, its delay, lies in
// [0, max_delay]. Until the delay is known, a frame takes the latest edge in that window (its
// exposure ended before the next trigger could start another). Each match teaches the delay (less
// half the reported exposure, so a new exposure does not move it; the median of the last nine);
// afterwards a frame's edge must lie within `tolerance` of it, and among several the one its frame
// counter expects after the last match (count), else the closest (time). Edges older than a matched one will never be claimed
// (frames come in order): they are dropped and counted as edges without a frame. So a missed edge
// costs only its own frame, and a dropped frame only its own edge; the next frame re-synchronizes
// by time. Three frames in a row whose candidate edges all miss the learned delay make it learned
// again (a camera whose clock mapping restarted).
//
// A frame that finds no edge in its window waits up to `edge_wait` for one, when the trigger is
// active and has not yet delivered anything later than the frame (the trigger's thread may run
// behind the camera's). Frames left without an edge pass on with their own time and are counted;
// they are reported as one kOther fault at most once a second (of frame time), with the count.
//
// Edges and frames may arrive on two threads: one mutex guards the state, held only to match; a
// frame's wait releases it. The ring of edges is allocated at construction: nothing is allocated
// per edge or frame (a forwarded frame shares its images).

#include <array>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "common/options_visitor.h"
#include "common/status.h"
#include "drivers/fault_throttle.h"
#include "hal/sensor_sink.h"

namespace cairn {

// `trigger.stamping:` of a profile.
struct TriggerFrameStamperOptions {
  double latency = 0.0;      // s from the edge to the exposure's start (the camera's trigger delay)
  double max_delay = 0.04;   // s, the latest a frame's own time may follow its edge
  double tolerance = 0.005;  // s, a matched edge's deviation from the learned delay; below half a period
  double edge_wait = 0.01;   // s a frame waits for an edge that is late
  int64_t edges = 64;        // edges kept for matching

  void Visit(OptionsVisitor& v) {
    v.Number("latency", latency, -1.0, 1.0, "s");
    v.Number("max_delay", max_delay, 0.0001, 10.0, "s");
    v.Number("tolerance", tolerance, 0.00001, 1.0, "s");
    v.Number("edge_wait", edge_wait, 0.0, 1.0, "s");
    v.Integer("edges", edges, 2, 4096, "edges");
  }
  Status Validate() const {
    if (tolerance >= max_delay) return InvalidArgumentError("tolerance must be below max_delay");
    return Status::Ok();
  }
};

struct TriggerFrameStamperCounts {
  uint64_t edges = 0;          // received
  uint64_t stamped = 0;        // frames forwarded at their edge's time
  uint64_t unmatched = 0;      // frames forwarded with their own time
  uint64_t lonely_edges = 0;   // edges no frame claimed (dropped frames)
  uint64_t relearns = 0;       // the delay learned again
  bool delay_learned = false;
  double delay = 0.0;          // s, learned frame time minus edge time, less half the exposure
};

class TriggerFrameStamper final : public SensorSink {
 public:
  // `next` receives everything and must outlive the stamper; `device` names its faults.
  TriggerFrameStamper(TriggerFrameStamperOptions options, SensorSink* next, std::string device);

  void OnImu(const ImuSample& sample) override { next_->OnImu(sample); }
  void OnStereo(const StereoFrame& frame) override;
  void OnWheelOdometry(const WheelOdometrySample& sample) override { next_->OnWheelOdometry(sample); }
  void OnTrigger(const TriggerEvent& event) override;
  void OnGnss(const GnssFix& fix) override { next_->OnGnss(fix); }
  void OnDeviceFault(const DeviceFault& fault) override { next_->OnDeviceFault(fault); }

  TriggerFrameStamperCounts counts() const;

 private:
  struct Edge {
    Timestamp time;
    uint64_t sequence = 0;
    bool used = false;
  };
  static constexpr size_t kDelays = 9;

  // Under mutex_: finds `frame`'s edge, its ring position (from the oldest) in *at.
  bool FindEdge(const StereoFrame& frame, size_t* at);
  // Under mutex_: marks the edge at `at` and every older unused one used.
  void Claim(size_t at);
  void Learn(Duration delay);
  void Forget();
  Edge& EdgeAt(size_t i) { return ring_[(oldest_ + i) % ring_.size()]; }

  const TriggerFrameStamperOptions options_;
  SensorSink* const next_;
  const std::string device_;
  const Duration latency_, max_delay_, tolerance_, edge_wait_;

  mutable std::mutex mutex_;
  std::condition_variable edge_arrived_;
  std::vector<Edge> ring_;
  size_t oldest_ = 0, size_ = 0;
  Timestamp newest_edge_;
  // The delay: the last ones matched, their median.
  std::array<int64_t, kDelays> delays_{};
  size_t delays_size_ = 0, delays_next_ = 0;
  Duration delay_;
  int misfits_ = 0;  // frames in a row whose candidates all missed the learned delay
  // The last match, for the count.
  bool have_match_ = false;
  uint64_t last_counter_ = 0, last_sequence_ = 0;
  FaultThrottle unmatched_throttle_;
  TriggerFrameStamperCounts counts_;
};

}  // namespace cairn
