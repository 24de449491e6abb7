#include "daemon/heap_policy.h"

#include <malloc.h>

#include <cstdio>

#include "common/sanitizers.h"

namespace cairn {
namespace {

// The "VmRSS:   1234 kB" and "VmHWM: ..." lines of /proc/self/status, in bytes; unset when absent.
void ReadResidentSet(HeapUse* u) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return;
  char line[256];
  long long kb = 0;
  while (std::fgets(line, sizeof(line), f) != nullptr) {
    if (std::sscanf(line, "VmRSS: %lld", &kb) == 1) u->rss_bytes = static_cast<int64_t>(kb) * 1024;
    if (std::sscanf(line, "VmHWM: %lld", &kb) == 1) u->peak_rss_bytes = static_cast<int64_t>(kb) * 1024;
  }
  std::fclose(f);
}

}  // namespace

bool HeapPolicy::Apply(std::string* why_not) {
#if CAIRN_ADDRESS_SANITIZER || CAIRN_THREAD_SANITIZER
  *why_not = "heap policy skipped in a sanitizer build";
  return false;
#else
  if (mallopt(M_MMAP_THRESHOLD, static_cast<int>(kMmapThreshold)) != 1) {
    *why_not = "mallopt(M_MMAP_THRESHOLD) refused";
    return false;
  }
  return true;
#endif
}

HeapUse HeapPolicy::Measure() {
  HeapUse u;
  const struct mallinfo2 m = mallinfo2();
  u.in_use_bytes = static_cast<int64_t>(m.uordblks + m.hblkhd);
  u.free_retained_bytes = static_cast<int64_t>(m.fordblks);
  u.mapped_bytes = static_cast<int64_t>(m.hblkhd);
  ReadResidentSet(&u);
  return u;
}

}  // namespace cairn
