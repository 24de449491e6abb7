#include "common/heap_bytes.h"

#include <malloc.h>

#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/sanitizers.h"

namespace cairn {
namespace {

TEST(HeapBytesTest, SumsTheCapacityOfEachContainer) {
  std::vector<double> a;
  a.reserve(10);
  a.push_back(1.0);
  std::vector<char> b(3);
  EXPECT_EQ(HeapBytes(a), 10 * sizeof(double));
  EXPECT_EQ(HeapBytes(a, b), 10 * sizeof(double) + b.capacity());
  EXPECT_EQ(HeapBytes(), 0u);
}

// The formula against glibc's own count of the heap in use, for the block sizes the octrees and
// small vectors allocate.
TEST(HeapBytesTest, BlockBytesMatchGlibcsCount) {
  if (CAIRN_ADDRESS_SANITIZER || CAIRN_THREAD_SANITIZER) GTEST_SKIP() << "the sanitizer replaces malloc";
  for (const size_t request : {size_t{1}, size_t{16}, size_t{24}, size_t{40}, size_t{64}, size_t{100}}) {
    constexpr size_t kCount = 20000;
    std::vector<std::unique_ptr<char[]>> blocks;
    blocks.reserve(kCount);
    const size_t before = mallinfo2().uordblks;
    for (size_t i = 0; i < kCount; ++i) blocks.emplace_back(new char[request]);
    const double per_block = static_cast<double>(mallinfo2().uordblks - before) / kCount;
    EXPECT_NEAR(per_block, static_cast<double>(HeapBlockBytes(request)), 0.5) << request << " bytes requested";
  }
  EXPECT_EQ(HeapBlockBytes(16), 32u);
  EXPECT_EQ(HeapBlockBytes(64), 80u);
}

}  // namespace
}  // namespace cairn
