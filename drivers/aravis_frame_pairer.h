#pragma once
// Pairs the frames of two cameras that take them together (triggered by one signal, or free
// running on the same period) for AravisStereoCamera, by their raw device timestamps, without
// relying on the host clock mappings of the two cameras to agree (each DeviceClockMapper carries
// its camera's transport delay until it settles: seconds, and far more than a pair's tolerance).
//
// For true partners the difference of the device times, left - right, is a constant, the pair
// offset, plus slow drift and the jitter of the two exposures' starts: about 0 when both cameras
// follow one PTP clock and are triggered together, the phase between them when they run free on
// one PTP clock, anything when each counts its own ticks. The pairer learns that offset:
//
//  - Learning. Candidate partners are matched by device time against a coarse offset: the
//    difference of the two cameras' lowest `arrival - device time` over their last frames (the
//    frames that waited least, so that one slow frame, a stall or a late start of one camera does
//    not move it), within half a frame period. The pair offset is the median of the last
//    candidates' differences; it is trusted once at least kAgreeing candidates, and more than half
//    of them, lie within `tolerance` of it. While learning nothing is published: the candidates
//    are dropped and counted, since a camera whose first frames came late makes its first
//    candidates wrong, but consistently wrong for only as long as it stays late.
//  - Locked. Two frames pair when their device time difference minus the offset is within
//    `tolerance`; each pair refines the offset (the median of the last pairs' differences, which
//    follows the drift of two independent clocks). A frame whose partner can no longer come (the
//    other camera's next frame is already later) is dropped and counted.
//  - Learning again: after Reset() (a reconnection: a reopened camera may have restarted its
//    clock), when a camera's device time goes backwards, after kRelearnAfter frames in a row
//    found no partner although the other camera had frames, or after kWindow pairs in a row whose
//    offset the coarse one contradicts by more than half a period (a lock learned while one camera
//    was late for all of the learning: its frames then pair a period or more apart until it is
//    prompt for a while).
//
// Frames waiting longer than `max_wait` (by arrival) for a partner are dropped and counted. No
// memory is allocated after construction: waiting frames and the offset windows are fixed rings.
//
// What the device times cannot tell: while one camera's frames all arrive more than half a period
// later than the other's (for longer than the coarse window of kWindow frames), it is
// indistinguishable from a camera whose clock is that much behind (without PTP): a lock learned
// then pairs frames a period or more apart until the delay ends, and a delay like that lasting
// kWindow pairs and more makes a right lock learned again, wrongly. Free-running cameras on
// independent clocks are paired nearest frame to nearest frame; how far apart their exposures
// are is then up to their phase, which only the host clock mappings can tell.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/timestamp.h"
#include "hal/image.h"

namespace cairn {

struct AravisFramePairerOptions {
  Duration period = Duration::Milliseconds(50);     // the frame period
  Duration tolerance = Duration::Milliseconds(2);   // largest jitter of a pair's device time difference
  Duration max_wait = Duration::Milliseconds(102);  // a frame waits this long for its partner
  int capacity = 8;                                 // frames waiting per camera
};

class AravisFramePairer {
 public:
  static constexpr int kWindow = 16;       // offset samples kept, per estimate
  static constexpr int kAgreeing = 5;      // candidates that must agree before pairs are published
  static constexpr int kRelearnAfter = 8;  // frames in a row without a partner

  struct Frame {
    Image image;
    int64_t device_time = 0;  // ns on the camera's clock
    Timestamp time;           // mapped to the host clock
    Timestamp arrival;
    uint64_t counter = 0;
  };

  explicit AravisFramePairer(const AravisFramePairerOptions& options);

  // Drops the waiting frames (uncounted) and learns the offset again.
  void Reset();
  // A frame of camera `side` (0 left, 1 right), in its camera's order. When `capacity` frames of
  // that camera wait already, the oldest is dropped (counted).
  void Add(int side, Frame&& frame);
  // The next pair, true when there is one (moved into `left` and `right`); frames that can no
  // longer pair, and those older than `max_wait` at `now`, are dropped on the way. Call until
  // false.
  bool Next(Timestamp now, Frame& left, Frame& right);

  bool locked() const { return locked_; }
  // The learned left - right device time difference of partners (ns); 0 while learning.
  int64_t offset_ns() const { return locked_ ? offset_ : 0; }
  uint64_t dropped() const { return dropped_; }      // frames dropped without a partner
  uint64_t relearned() const { return relearned_; }  // times the offset was learned again (not Reset)

 private:
  // A fixed ring of T, oldest first.
  template <class T>
  class Ring {
   public:
    explicit Ring(size_t capacity) : items_(capacity) {}
    bool empty() const { return size_ == 0; }
    bool full() const { return size_ == items_.size(); }
    size_t size() const { return size_; }
    T& front() { return items_[head_]; }
    const T& operator[](size_t i) const { return items_[(head_ + i) % items_.size()]; }
    void push_back(T&& v) {  // the oldest is overwritten when full
      if (full()) pop_front();
      items_[(head_ + size_) % items_.size()] = std::move(v);
      ++size_;
    }
    void pop_front() {
      items_[head_] = T();  // releases what it holds (an image's buffer)
      head_ = (head_ + 1) % items_.size();
      --size_;
    }
    void clear() {
      while (!empty()) pop_front();
    }

   private:
    std::vector<T> items_;
    size_t head_ = 0, size_ = 0;
  };

  void Drop(int side);
  void Unlock();
  int64_t CoarseOffset() const;
  // The median of the samples; `agreeing`: how many lie within `tolerance` of it.
  int64_t Median(int* agreeing) const;
  void AddSample(int64_t difference);

  AravisFramePairerOptions options_;
  Ring<Frame> waiting_[2];
  Ring<int64_t> delays_[2];  // arrival - device time (ns) of each camera's last frames
  Ring<int64_t> samples_;    // left - right device times of the last candidates or pairs
  bool locked_ = false;
  int64_t offset_ = 0;
  int misses_ = 0;
  int disagreements_ = 0;  // pairs in a row whose offset the coarse one contradicts
  bool have_last_[2] = {false, false};
  int64_t last_device_[2] = {0, 0};
  uint64_t dropped_ = 0, relearned_ = 0;
};

}  // namespace cairn
