#include "daemon/heap_policy.h"

#include <malloc.h>

#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

#include "common/sanitizers.h"

namespace cairn {
namespace {

// Allocates, writes and keeps a block until destroyed.
struct Block {
  explicit Block(size_t n) : p(static_cast<char*>(std::malloc(n))) { std::memset(p, 1, n); }
  ~Block() { std::free(p); }
  Block(const Block&) = delete;
  Block& operator=(const Block&) = delete;
  char* p;
};

TEST(HeapPolicyTest, LargeBlocksStayMappedAfterALargerOneWasFreed) {
  std::string why;
  if (CAIRN_ADDRESS_SANITIZER || CAIRN_THREAD_SANITIZER) {
    EXPECT_FALSE(HeapPolicy::Apply(&why));
    GTEST_SKIP() << why;
  }
  ASSERT_TRUE(HeapPolicy::Apply(&why)) << why;
  // Free heap that earlier tests in this process left would serve the block without a mapping.
  malloc_trim(0);
  // By default glibc would now serve blocks below 8 MB from the heap (its threshold follows the
  // largest mapped block freed); with the policy, a 1 MB block is still mapped.
  { Block big(size_t{8} << 20); }
  const int64_t mapped_before = HeapPolicy::Measure().mapped_bytes;
  Block mid(size_t{1} << 20);
  EXPECT_GE(HeapPolicy::Measure().mapped_bytes - mapped_before, int64_t{1} << 20);
}

TEST(HeapPolicyTest, MeasuresTheProcess) {
  Block b(size_t{4} << 20);
  const HeapUse u = HeapPolicy::Measure();
  // A sanitizer's allocator keeps glibc's counters at zero.
  if (!(CAIRN_ADDRESS_SANITIZER || CAIRN_THREAD_SANITIZER)) {
    EXPECT_GE(u.in_use_bytes, int64_t{4} << 20);
  }
  EXPECT_GE(u.rss_bytes, int64_t{4} << 20);
  EXPECT_GE(u.peak_rss_bytes, u.rss_bytes);
  EXPECT_GE(u.in_use_bytes, u.mapped_bytes);
}

}  // namespace
}  // namespace cairn
