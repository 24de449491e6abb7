#include "daemon/heap_policy.h"

#include <malloc.h>

#include <cstdio>
#include <cstring>

#include "common/sanitizers.h"

namespace cairn {
namespace {

// A "VmRSS:   1234 kB" line of /proc/self/status, in bytes; 0 when absent.
int64_t StatusKilobytes(const char* key) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (f == nullptr) return 0;
  char line[256];
  int64_t value = 0;
  const size_t n = std::strlen(key);
  while (std::fgets(line, sizeof(line), f) != nullptr) {
    if (std::strncmp(line, key, n) == 0 && line[n] == ':') {
      long long kb = 0;
      if (std::sscanf(line + n + 1, "%lld", &kb) == 1) value = static_cast<int64_t>(kb) * 1024;
      break;
    }
  }
  std::fclose(f);
  return value;
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
  u.rss_bytes = StatusKilobytes("VmRSS");
  u.peak_rss_bytes = StatusKilobytes("VmHWM");
  return u;
}

}  // namespace cairn
