#pragma once
// How the process's heap behaves over a long mission, and what it holds.
//
// glibc raises its mmap threshold each time a large block it had mapped is freed, so later large
// blocks (voxel tables, descriptor arrays, scratch of megabytes) come from the heap instead. There
// they are freed between the small long-lived blocks of finished submaps, and the holes cannot be
// returned, least of all with memory locked: a simulated rover's resident memory grew by about
// 9.5 MB per submap of which about 5 MB was free heap nobody could use. A fixed threshold keeps
// large blocks mapped, so freeing one gives its pages back.

#include <cstddef>
#include <cstdint>
#include <string>

namespace cairn {

struct HeapUse {
  int64_t in_use_bytes = 0;         // allocated blocks, heap and mapped
  int64_t free_retained_bytes = 0;  // free inside the heap, still resident
  int64_t mapped_bytes = 0;         // blocks mapped on their own (part of in_use_bytes)
  int64_t rss_bytes = 0;            // resident set of the process
  int64_t peak_rss_bytes = 0;       // its high-water mark
};

class HeapPolicy {
 public:
  // Blocks of at least this size are mapped on their own and unmapped when freed.
  static constexpr size_t kMmapThreshold = size_t{128} << 10;

  // Fixes the threshold for the process. False, with the reason, under a sanitizer (its own
  // allocator ignores glibc's settings) or where glibc refuses.
  static bool Apply(std::string* why_not);
  // glibc's counters and /proc/self/status; fields stay zero where unavailable.
  static HeapUse Measure();
};

}  // namespace cairn
