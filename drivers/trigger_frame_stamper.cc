#include "drivers/trigger_frame_stamper.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace cairn {
namespace {

// An edge this close to a frame's time means the trigger is running: a frame without its edge
// then waits for it. Farther (no trigger, or one on another clock), frames do not wait.
constexpr Duration kStamperActiveWindow = Duration::Seconds(1.0);
// Frames in a row whose candidate edges miss the learned delay before it is learned again.
constexpr int kStamperMisfitsToRelearn = 3;

}  // namespace

TriggerFrameStamper::TriggerFrameStamper(TriggerFrameStamperOptions options, SensorSink* next, std::string device)
    : options_(options),
      next_(next),
      device_(std::move(device)),
      latency_(Duration::Seconds(options.latency)),
      max_delay_(Duration::Seconds(options.max_delay)),
      tolerance_(Duration::Seconds(options.tolerance)),
      edge_wait_(Duration::Seconds(options.edge_wait)),
      ring_(static_cast<size_t>(std::max<int64_t>(2, options.edges))) {}

TriggerFrameStamperCounts TriggerFrameStamper::counts() const {
  std::lock_guard lock(mutex_);
  TriggerFrameStamperCounts c = counts_;
  c.delay_learned = delays_size_ > 0;
  c.delay = delay_.seconds();
  return c;
}

void TriggerFrameStamper::OnTrigger(const TriggerEvent& event) {
  {
    std::lock_guard lock(mutex_);
    if (size_ == ring_.size()) {
      // The oldest goes; a frame that never claimed it is not coming any more.
      if (!EdgeAt(0).used) ++counts_.lonely_edges;
      oldest_ = (oldest_ + 1) % ring_.size();
      --size_;
    }
    EdgeAt(size_) = Edge{event.time, event.sequence, false};
    ++size_;
    newest_edge_ = event.time;
    ++counts_.edges;
  }
  edge_arrived_.notify_all();
  next_->OnTrigger(event);
}

void TriggerFrameStamper::Learn(Duration delay) {
  delays_[delays_next_] = delay.nanoseconds();
  delays_next_ = (delays_next_ + 1) % kDelays;
  delays_size_ = std::min(delays_size_ + 1, kDelays);
  std::array<int64_t, kDelays> sorted = delays_;
  const auto end = sorted.begin() + static_cast<std::ptrdiff_t>(delays_size_);
  const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>(delays_size_ / 2);
  std::nth_element(sorted.begin(), middle, end);
  delay_ = Duration::Nanoseconds(*middle);
}

void TriggerFrameStamper::Forget() {
  delays_size_ = delays_next_ = 0;
  delay_ = Duration();
  have_match_ = false;
  misfits_ = 0;
  ++counts_.relearns;
}

bool TriggerFrameStamper::FindEdge(const StereoFrame& frame, size_t* at) {
  const bool learned = delays_size_ > 0;
  const Duration half_exposure = frame.exposure / 2;
  // The edge the frame counter expects after the last match.
  const bool counting = have_match_ && frame.frame_counter > last_counter_;
  const uint64_t expected = last_sequence_ + (frame.frame_counter - last_counter_);
  size_t fitting = 0, in_window = 0;
  Duration best = Duration::Nanoseconds(INT64_MAX);
  bool by_count = false;
  for (size_t i = 0; i < size_; ++i) {
    const Edge& e = EdgeAt(i);
    const Duration delay = frame.time - e.time;
    if (e.used || delay < Duration() || delay > max_delay_) continue;
    ++in_window;
    const Duration error = delay - half_exposure - delay_;
    const Duration distance = error < Duration() ? -error : error;
    if (learned && distance > tolerance_) continue;
    ++fitting;
    // Count first; then the delay closest to the learned one or, before one is learned, the
    // shortest: the exposure ends before the next trigger, so a frame follows its own edge by
    // less than a period.
    const Duration score = learned ? distance : delay;
    if (!by_count && ((counting && e.sequence == expected) || score < best)) {
      by_count = counting && e.sequence == expected;
      best = score;
      *at = i;
    }
  }
  if (fitting == 0 && learned && in_window > 0 && ++misfits_ >= kStamperMisfitsToRelearn) {
    Forget();
    return FindEdge(frame, at);  // once more, as before anything was learned
  }
  return fitting > 0;
}

void TriggerFrameStamper::Claim(size_t at) {
  for (size_t i = 0; i < at; ++i) {
    Edge& e = EdgeAt(i);
    if (!e.used) ++counts_.lonely_edges;
    e.used = true;
  }
  EdgeAt(at).used = true;
}

void TriggerFrameStamper::OnStereo(const StereoFrame& frame) {
  StereoFrame out = frame;  // shares the images: only the time changes
  uint64_t report = 0;
  Duration since_edge;
  bool unmatched = false, have_edge = false;
  {
    std::unique_lock lock(mutex_);
    size_t at = 0;
    bool found = FindEdge(frame, &at);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::nanoseconds(edge_wait_.nanoseconds());
    while (!found && counts_.edges > 0 && newest_edge_ < frame.time &&
           frame.time - newest_edge_ <= kStamperActiveWindow) {
      const uint64_t seen = counts_.edges;
      if (!edge_arrived_.wait_until(lock, deadline, [&] { return counts_.edges != seen; })) break;
      found = FindEdge(frame, &at);
    }
    if (found) {
      const Edge& e = EdgeAt(at);
      Learn(frame.time - e.time - frame.exposure / 2);
      misfits_ = 0;
      have_match_ = true;
      last_counter_ = frame.frame_counter;
      last_sequence_ = e.sequence;
      out.time = e.time + latency_ + frame.exposure / 2;
      Claim(at);
      ++counts_.stamped;
      report = unmatched_throttle_.Add(0, frame.time);
    } else {
      unmatched = true;
      ++counts_.unmatched;
      report = unmatched_throttle_.Add(1, frame.time);
    }
    have_edge = counts_.edges > 0;
    since_edge = frame.time - newest_edge_;
  }
  if (report > 0) {
    // Rare (once a second at most): the only place the stamper formats text.
    char detail[256];
    const int n = std::snprintf(detail, sizeof detail,
                                "%llu frames passed on with their own time since the last report: no trigger "
                                "edge within [0, %g] s before them",
                                static_cast<unsigned long long>(report), options_.max_delay);
    if (unmatched && n > 0 && static_cast<size_t>(n) < sizeof detail) {
      if (have_edge) {
        std::snprintf(detail + n, sizeof detail - static_cast<size_t>(n),
                      " (this frame's time minus the newest edge's: %.6f s)", since_edge.seconds());
      } else {
        std::snprintf(detail + n, sizeof detail - static_cast<size_t>(n), " (no edge received yet)");
      }
    }
    next_->OnDeviceFault(DeviceFault{frame.time, device_, DeviceFaultKind::kOther, detail});
  }
  next_->OnStereo(out);
}

}  // namespace cairn
