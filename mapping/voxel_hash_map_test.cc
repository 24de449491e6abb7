#include "mapping/voxel_hash_map.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

// Tables past 2 MB come from the huge-page allocator: growing into one, clearing and refilling it
// keep every entry.
TEST(VoxelHashMapTest, LargeTablesKeepEntriesThroughGrowthAndClear) {
  VoxelHashMap<uint32_t> map(16);
  const auto key = [](int i) { return VoxelKey::Pack(i % 97 - 40, (i / 97) % 89 - 30, i / (97 * 89) - 5); };
  constexpr int kN = 300000;  // 16-byte slots, >= 2^20 of them: 16 MB
  for (int round = 0; round < 2; ++round) {
    for (int i = 0; i < kN; ++i) map[key(i)] = static_cast<uint32_t>(i + round);
    ASSERT_EQ(map.size(), static_cast<size_t>(kN));
    for (int i = 0; i < kN; i += 7) {
      const uint32_t* v = map.Find(key(i));
      ASSERT_NE(v, nullptr);
      EXPECT_EQ(*v, static_cast<uint32_t>(i + round));
    }
    EXPECT_EQ(map.Find(VoxelKey::Pack(1000, 1000, 1000)), nullptr);
    map.Clear();
    EXPECT_TRUE(map.empty());
  }
}

}  // namespace
}  // namespace cairn
