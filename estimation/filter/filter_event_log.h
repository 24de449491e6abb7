#pragma once
// The local reference filter's event log: clones, releases and measurements in time order, in a
// ring addressed by ever-increasing sequence numbers. [begin, next) are processed and kept for
// replays, [next, end) wait for the IMU data to reach their time. The ring is allocated by the
// constructor; no operation allocates afterwards.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/timestamp.h"
#include "estimation/filter/filter_event.h"

namespace cairn {

class FilterEventLog {
 public:
  explicit FilterEventLog(size_t capacity);

  size_t capacity() const { return events_.size(); }
  uint64_t size() const { return end_ - begin_; }
  uint64_t begin_seq() const { return begin_; }
  uint64_t next_seq() const { return next_; }
  uint64_t end_seq() const { return end_; }

  // The event with sequence number `seq`, in [begin_seq, end_seq).
  FilterEvent& at(uint64_t seq) { return events_[seq % events_.size()]; }
  const FilterEvent& at(uint64_t seq) const { return events_[seq % events_.size()]; }

  // Where an event at `time` goes: after every kept event at or before that time.
  uint64_t InsertPosition(Timestamp time) const;
  // Makes room for one more event by dropping the oldest processed one when full (its replay
  // start becomes unusable). False when full of pending events, which stay.
  bool MakeRoom();
  // Inserts `e` at `pos` in [begin_seq, end_seq], moving the later events up by one. Needs room
  // (MakeRoom).
  void Insert(uint64_t pos, const FilterEvent& e);

  // Marks the oldest pending event as processed.
  void Advance() { ++next_; }
  // Makes the events from `seq` on pending again (a replay from a saved state).
  void Rewind(uint64_t seq) { next_ = seq; }
  // Forgets the events before `seq` (no replay starts before it any more).
  void DropBefore(uint64_t seq);
  // Forgets all processed events.
  void DropProcessed() { begin_ = next_; }

 private:
  std::vector<FilterEvent> events_;
  uint64_t begin_ = 0, next_ = 0, end_ = 0;
};

}  // namespace cairn
