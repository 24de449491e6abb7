#include "common/heap_bytes.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace cairn
