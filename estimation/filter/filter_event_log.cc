#include "estimation/filter/filter_event_log.h"

#include <algorithm>

namespace cairn {

FilterEventLog::FilterEventLog(size_t capacity) : events_(std::max<size_t>(capacity, 1)) {}

uint64_t FilterEventLog::InsertPosition(Timestamp time) const {
  uint64_t pos = end_;
  while (pos > begin_ && at(pos - 1).time > time) --pos;
  return pos;
}

bool FilterEventLog::MakeRoom() {
  if (end_ - begin_ < events_.size()) return true;
  if (begin_ >= next_) return false;
  ++begin_;
  return true;
}

void FilterEventLog::Insert(uint64_t pos, const FilterEvent& e) {
  for (uint64_t s = end_; s > pos; --s) at(s) = at(s - 1);
  at(pos) = e;
  ++end_;
}

void FilterEventLog::DropBefore(uint64_t seq) { begin_ = std::max(begin_, seq); }

}  // namespace cairn
