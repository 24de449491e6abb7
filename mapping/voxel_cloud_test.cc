#include "mapping/voxel_cloud.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <tuple>

#include <gtest/gtest.h>

namespace cairn {
namespace {

using Key = std::tuple<int, int, int>;

std::map<Key, CloudPoint> ByVoxel(const std::vector<CloudPoint>& points, double res) {
  std::map<Key, CloudPoint> m;
  for (const CloudPoint& c : points) {
    // Centroids lie in [corner, corner + 0.999 res]: the nudge keeps rounding off the boundary.
    const Eigen::Vector3i k = (c.p.cast<double>() / res).array().unaryExpr([](double s) { return std::floor(s + 1e-4); }).cast<int>();
    EXPECT_TRUE(m.emplace(Key{k.x(), k.y(), k.z()}, c).second) << "two centroids in one voxel";
  }
  return m;
}

// AddBatch sums an image's points per voxel in a small cache before they reach the table; the
// centroids, gray values and obstacle flags must be those of adding every point on its own, also
// when far more voxels than the cache holds interleave (evictions) and after earlier images.
TEST(VoxelCloudTest, AddBatchEqualsAddingEachPoint) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  VoxelCloud batch(0.05), single(0.05);
  for (int image = 0; image < 3; ++image) {
    std::vector<Eigen::Vector3f> p;
    std::vector<uint8_t> gray, obstacle;
    // Rows of a noisy surface 2..6 m away (neighbouring points alternate between depth layers),
    // then scattered points over a 40 m cube (one voxel each, more voxels than the cache holds).
    for (int v = 0; v < 200; ++v) {
      for (int k = 0; k < 300; ++k) {
        const float x = 2.0f + 4.0f * static_cast<float>(v) / 200.0f + 0.03f * u(rng);
        p.emplace_back(x, -1.5f + 0.01f * static_cast<float>(k) + 0.2f * static_cast<float>(image), 0.1f * u(rng) - 20.0f);
      }
    }
    for (int k = 0; k < 20000; ++k) {
      const float z = 40.0f * u(rng) - 20.0f, y = 40.0f * u(rng) - 20.0f, x = 40.0f * u(rng) - 20.0f;
      p.emplace_back(x, y, z);
    }
    p.emplace_back(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f);
    p.emplace_back(1e9f, 0.0f, 0.0f);
    for (size_t i = 0; i < p.size(); ++i) {
      gray.push_back(static_cast<uint8_t>(rng() & 0xFF));
      obstacle.push_back((rng() % 50) == 0);
    }
    EXPECT_EQ(batch.AddBatch(p, gray, obstacle), 2u);
    for (size_t i = 0; i < p.size(); ++i) single.Add(p[i], gray[i], gray[i], gray[i], obstacle[i] != 0);
  }
  const auto a = ByVoxel(batch.Points(), 0.05), b = ByVoxel(single.Points(), 0.05);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_GT(a.size(), 60000u);
  int64_t obstacles = 0;
  for (const auto& [key, pa] : a) {
    const auto it = b.find(key);
    ASSERT_NE(it, b.end());
    const CloudPoint& pb = it->second;
    // The same sums, grouped differently: float rounding only.
    EXPECT_LT((pa.p - pb.p).norm(), 1e-5f);
    EXPECT_EQ(pa.r, pb.r);
    EXPECT_EQ(pa.g, pb.g);
    EXPECT_EQ(pa.b, pb.b);
    EXPECT_EQ(pa.obstacle, pb.obstacle);
    obstacles += pa.obstacle;
  }
  EXPECT_GT(obstacles, 100);
}

}  // namespace
}  // namespace cairn
