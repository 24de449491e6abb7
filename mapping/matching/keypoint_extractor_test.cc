#include "mapping/matching/keypoint_extractor.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/occupancy_integrator.h"
#include "mapping/testing/rock_field_scene.h"
#include "mapping/testing/submap_test_util.h"

namespace cairn {
namespace {

CloudPoint Obstacle(float x, float y, float z, bool obstacle = true) {
  CloudPoint c;
  c.p = Eigen::Vector3f(x, y, z);
  c.obstacle = obstacle ? 1 : 0;
  return c;
}

TEST(KeypointExtractorTest, OneCentroidPerVoxelOfObstaclePoints) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<CloudPoint> points = {Obstacle(0.01f, 0.02f, 0.03f),        Obstacle(0.05f, 0.06f, 0.07f),
                                          Obstacle(0.09f, 0.09f, 0.09f, false), Obstacle(0.25f, 0.01f, 0.01f),
                                          Obstacle(-0.05f, 0.01f, 0.01f),       Obstacle(nan, 0.0f, 0.0f),
                                          Obstacle(0.0f, 1e30f, 0.0f)};
  const SubmapKeypoints k = KeypointExtractor().VoxelKeypoints(points);
  EXPECT_EQ(k.non_finite_points, 2);  // NaN, and a point beyond the key range
  EXPECT_EQ(k.obstacle_points, 4);
  ASSERT_EQ(k.points.size(), 3u);
  EXPECT_EQ(k.voxel_keypoints, 3);
  auto has = [&](const Eigen::Vector3f& p) {
    return std::any_of(k.points.begin(), k.points.end(),
                       [&](const Eigen::Vector3f& q) { return (q - p).norm() < 1e-5f; });
  };
  EXPECT_TRUE(has({0.03f, 0.04f, 0.05f}));
  EXPECT_TRUE(has({0.25f, 0.01f, 0.01f}));
  EXPECT_TRUE(has({-0.05f, 0.01f, 0.01f}));
}

// A tree known (free) for x < 0 and unknown beyond, with a wall of obstacle points along x.
std::shared_ptr<const Submap> HalfKnownSubmap() {
  std::unique_ptr<octomap::OcTree> tree = MakeOccupancyTree(SubmapOptions{});
  for (double x = -1.95; x < 0.0; x += 0.1) {
    for (double y = -0.95; y < 1.0; y += 0.1) {
      for (double z = -0.45; z < 0.9; z += 0.1) tree->updateNode(octomap::point3d(x, y, z), false);
    }
  }
  tree->updateInnerOccupancy();
  std::vector<CloudPoint> points;
  for (float x = -1.6f; x <= 1.6f; x += 0.05f) {
    for (float z = 0.1f; z <= 0.5f; z += 0.05f) points.push_back(Obstacle(x, 0.02f, z));
  }
  return std::make_shared<const Submap>(SubmapMetadata{}, std::move(points), std::move(tree));
}

TEST(KeypointExtractorTest, DropsKeypointsWithLittleKnownSpace) {
  const auto submap = HalfKnownSubmap();
  const KeypointExtractor extractor;
  EXPECT_DOUBLE_EQ(extractor.KnownFraction(submap->tree(), {-1.0f, 0.0f, 0.3f}), 1.0);
  EXPECT_DOUBLE_EQ(extractor.KnownFraction(submap->tree(), {1.0f, 0.0f, 0.3f}), 0.0);
  const double half = extractor.KnownFraction(submap->tree(), {0.0f, 0.0f, 0.3f});
  EXPECT_GT(half, 0.3);
  EXPECT_LT(half, 0.7);

  const SubmapKeypoints k = extractor.Extract(*submap);
  ASSERT_GT(k.voxel_keypoints, 100);
  EXPECT_GT(k.dropped_unknown, 50);
  EXPECT_EQ(static_cast<int64_t>(k.points.size()) + k.dropped_unknown, k.voxel_keypoints);
  ASSERT_EQ(k.points.size(), k.known_fraction.size());
  int kept_left = 0;
  for (size_t i = 0; i < k.points.size(); ++i) {
    EXPECT_LT(k.points[i].x(), 0.0f) << "kept a keypoint in unknown space";
    EXPECT_GE(k.known_fraction[i], 0.8f);
    if (k.points[i].x() < -0.3f) ++kept_left;
  }
  // Every keypoint whose sphere lies inside the known half is kept.
  const SubmapKeypoints voxels = extractor.VoxelKeypoints(submap->points());
  const auto left = std::count_if(voxels.points.begin(), voxels.points.end(),
                                  [](const Eigen::Vector3f& p) { return p.x() < -0.3f; });
  EXPECT_GT(left, 40);
  EXPECT_EQ(kept_left, left);

  KeypointExtractorOptions all;
  all.min_known_fraction = 0.0;
  EXPECT_EQ(KeypointExtractor(all).Extract(*submap).dropped_unknown, 0);
}

// How much of a descriptor sphere is known in ray-cast submaps: for the report, and so the default
// threshold's effect is visible in the test log.
void PrintKnownFractions(const char* name, const Submap& submap) {
  const KeypointExtractor extractor;
  const SubmapKeypoints k = extractor.VoxelKeypoints(submap.points());
  std::vector<double> f;
  for (const Eigen::Vector3f& p : k.points) f.push_back(extractor.KnownFraction(submap.tree(), p));
  ASSERT_FALSE(f.empty());
  std::sort(f.begin(), f.end());
  auto q = [&](double x) { return f[static_cast<size_t>(x * static_cast<double>(f.size() - 1))]; };
  const auto at_least = [&](double t) {
    return static_cast<double>(f.end() - std::lower_bound(f.begin(), f.end(), t)) /
           static_cast<double>(f.size());
  };
  std::printf(
      "[ known   ] %s: %zu keypoints, known fraction q10 %.2f q50 %.2f q90 %.2f; kept at >= 0.8: %.0f %%, "
      "at known/unknown >= 0.8 (fraction >= 0.444): %.0f %%\n",
      name, f.size(), q(0.1), q(0.5), q(0.9), 100.0 * at_least(0.8), 100.0 * at_least(0.8 / 1.8));
  EXPECT_GE(f.front(), 0.0);
  EXPECT_LE(f.back(), 1.0);
}

TEST(KeypointExtractorTest, KnownSpaceOfRayCastSubmaps) {
  PrintKnownFractions("ridge submap (mapping/testing)", *testing::SyntheticSubmap(1));
  testing::RockFieldOptions o;
  testing::SceneSubmapOptions so;
  so.viewpoints = {{-4.0, -2.0, 1.5}, {-2.0, 2.0, 1.5}, {0.0, -2.0, 1.5}, {2.0, 2.0, 1.5}, {4.0, -2.0, 1.5}};
  PrintKnownFractions("rock field",
                      *testing::SceneSubmap(testing::RockField(o), Eigen::Isometry3d::Identity(), so));
}

}  // namespace
}  // namespace cairn
