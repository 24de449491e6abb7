#include "drivers/aravis_frame_pairer.h"

#include <algorithm>
#include <limits>

namespace cairn {

AravisFramePairer::AravisFramePairer(const AravisFramePairerOptions& options)
    : options_(options),
      waiting_{Ring<Frame>(static_cast<size_t>(std::max(1, options.capacity))),
               Ring<Frame>(static_cast<size_t>(std::max(1, options.capacity)))},
      delays_{Ring<int64_t>(kWindow), Ring<int64_t>(kWindow)},
      samples_(kWindow) {}

void AravisFramePairer::Reset() {
  for (int side : {0, 1}) {
    waiting_[side].clear();
    delays_[side].clear();
    have_last_[side] = false;
  }
  Unlock();
}

void AravisFramePairer::Unlock() {
  locked_ = false;
  offset_ = 0;
  misses_ = 0;
  disagreements_ = 0;
  samples_.clear();
}

void AravisFramePairer::Drop(int side) {
  waiting_[side].pop_front();
  ++dropped_;
}

void AravisFramePairer::Add(int side, Frame&& frame) {
  if (have_last_[side] && frame.device_time < last_device_[side]) {
    // The camera restarted its clock: its waiting frames and the offset belong to the old one.
    while (!waiting_[side].empty()) Drop(side);
    delays_[side].clear();
    if (locked_) ++relearned_;
    Unlock();
  }
  have_last_[side] = true;
  last_device_[side] = frame.device_time;
  delays_[side].push_back(frame.arrival.nanoseconds() - frame.device_time);
  if (waiting_[side].full()) Drop(side);
  waiting_[side].push_back(std::move(frame));
}

int64_t AravisFramePairer::CoarseOffset() const {
  int64_t lowest[2] = {std::numeric_limits<int64_t>::max(), std::numeric_limits<int64_t>::max()};
  for (int side : {0, 1})
    for (size_t i = 0; i < delays_[side].size(); ++i) lowest[side] = std::min(lowest[side], delays_[side][i]);
  // arrival = device time + offset + delay: partners' host times agree, so left - right device
  // time = right offset - left offset, the offsets taken as the least delayed differences.
  return lowest[1] - lowest[0];
}

int64_t AravisFramePairer::Median(int* agreeing) const {
  std::array<int64_t, kWindow> v{};
  const size_t n = samples_.size();
  for (size_t i = 0; i < n; ++i) v[i] = samples_[i];
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2),
                   v.begin() + static_cast<std::ptrdiff_t>(n));
  const int64_t median = v[n / 2];
  if (agreeing != nullptr) {
    const int64_t tolerance = options_.tolerance.nanoseconds();
    *agreeing =
        static_cast<int>(std::count_if(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n), [&](int64_t s) {
          return s - median <= tolerance && median - s <= tolerance;
        }));
  }
  return median;
}

void AravisFramePairer::AddSample(int64_t difference) { samples_.push_back(std::move(difference)); }

bool AravisFramePairer::Next(Timestamp now, Frame& left, Frame& right) {
  Ring<Frame>& l = waiting_[0];
  Ring<Frame>& r = waiting_[1];
  const int64_t tolerance = options_.tolerance.nanoseconds();
  const int64_t half_period = options_.period.nanoseconds() / 2;
  while (!l.empty() && !r.empty()) {
    const int64_t difference = l.front().device_time - r.front().device_time;
    if (locked_) {
      const int64_t d = difference - offset_;
      if (d > tolerance || d < -tolerance) {
        // The later of the two is not the earlier one's partner, which can no longer come (each
        // camera's frames come in order): the earlier one goes.
        Drop(d > tolerance ? 1 : 0);
        if (++misses_ >= kRelearnAfter) {
          ++relearned_;
          Unlock();
        }
        continue;
      }
      // A lock learned from candidates that were all wrong (a camera late for all of the learning)
      // holds partners a period or more apart: the coarse offset shows it once that camera's frames
      // come promptly.
      const int64_t coarse = CoarseOffset();
      if (offset_ - coarse > half_period || coarse - offset_ > half_period) {
        if (++disagreements_ >= kWindow) {
          ++relearned_;
          Unlock();
          continue;  // these two are the first candidates
        }
      } else {
        disagreements_ = 0;
      }
      misses_ = 0;
      AddSample(difference);
      offset_ = Median(nullptr);
      left = std::move(l.front());
      right = std::move(r.front());
      l.pop_front();
      r.pop_front();
      return true;
    }
    const int64_t d = difference - CoarseOffset();
    if (d > half_period) {
      Drop(1);
      continue;
    }
    if (d < -half_period) {
      Drop(0);
      continue;
    }
    // A candidate: its difference is a sample, its frames are not published.
    AddSample(difference);
    Drop(0);
    Drop(1);
    int agreeing = 0;
    const int64_t median = Median(&agreeing);
    if (agreeing >= kAgreeing && 2 * static_cast<size_t>(agreeing) > samples_.size()) {
      // Only the agreeing samples go on: the others were wrong partners.
      std::array<int64_t, kWindow> keep{};
      size_t n = 0;
      for (size_t i = 0; i < samples_.size(); ++i) {
        const int64_t s = samples_[i];
        if (s - median <= tolerance && median - s <= tolerance) keep[n++] = s;
      }
      samples_.clear();
      for (size_t i = 0; i < n; ++i) samples_.push_back(std::move(keep[i]));
      locked_ = true;
      offset_ = Median(nullptr);
      misses_ = 0;
    }
  }
  for (int side : {0, 1}) {
    while (!waiting_[side].empty() && now - waiting_[side].front().arrival > options_.max_wait) Drop(side);
  }
  return false;
}

}  // namespace cairn
