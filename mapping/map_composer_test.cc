#include "mapping/map_composer.h"

#include <cmath>
#include <unordered_map>
#include <numbers>

#include <gtest/gtest.h>

#include "mapping/testing/submap_test_util.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

std::shared_ptr<const Submap> FromTree(std::unique_ptr<octomap::OcTree> tree, uint64_t id) {
  SubmapMetadata m;
  m.robot = "geb";
  m.id = id;
  m.options.octree_resolution = tree->getResolution();
  return std::make_shared<const Submap>(m, std::vector<CloudPoint>{}, std::move(tree));
}

// Finest-level log-odds of every known voxel (pruned leaves expanded).
using VoxelMap = std::unordered_map<uint64_t, float>;
uint64_t Key(int x, int y, int z) { return VoxelKey::Pack(x - 32768, y - 32768, z - 32768); }

VoxelMap Voxels(const octomap::OcTree& t) {
  VoxelMap out;
  const int depth = static_cast<int>(t.getTreeDepth());
  for (auto it = t.begin_leafs(); it != t.end_leafs(); ++it) {
    const int n = 1 << (depth - static_cast<int>(it.getDepth()));
    const octomap::OcTreeKey k = it.getIndexKey();
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) out[Key(k[0] + x, k[1] + y, k[2] + z)] = it->getLogOdds();
  }
  return out;
}

// Thesis 5.2.2: merging two maps sums their log-odds and clamps. geb079 and a copy shifted by a
// whole number of voxels: every voxel of the result is clamp(a + b) of the voxels that meet there.
TEST(MapComposerTest, GebMergedWithShiftedCopyGivesSummedClampedLogOdds) {
  const std::string path = testing::DataDir() + "/octomap/geb079.bt";
  CAIRN_REQUIRE_PATH(path);
  // Read into a tree with the thesis' clamping: .bt leaves load as the clamping bounds -2 / 3.5.
  auto a = MakeOccupancyTree(SubmapOptions{});
  ASSERT_TRUE(a->readBinary(path));
  const double res = a->getResolution();
  SubmapOptions so;
  so.octree_resolution = res;
  auto b = std::make_unique<octomap::OcTree>(*a);
  const auto va = Voxels(*a);
  MapComposer composer(CompositionOptions{}, so);
  const int sx = 20, sy = -7;  // shift in voxels
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation() = Eigen::Vector3d(sx * res, sy * res, 0.0);
  ASSERT_TRUE(composer.SetSubmap(FromTree(std::move(a), 1), Eigen::Isometry3d::Identity()).ok());
  ASSERT_TRUE(composer.SetSubmap(FromTree(std::move(b), 2), shift).ok());
  const CompositionStats st = composer.Update();
  EXPECT_EQ(st.rebuilt, 2);
  const auto merged = Voxels(*composer.Octree());
  VoxelMap expected = va;
  for (const auto& [k, v] : va) {
    const Eigen::Vector3i c = VoxelKey::Unpack(k);
    const uint64_t ks = VoxelKey::Pack(c.x() + sx, c.y() + sy, c.z());
    auto it = expected.find(ks);
    if (it == expected.end()) expected[ks] = v;
    else it->second = std::clamp(it->second + v, -2.0f, 3.5f);
  }
  ASSERT_EQ(merged.size(), expected.size());
  int both_occupied = 0, mixed = 0;
  for (const auto& [k, v] : expected) {
    auto it = merged.find(k);
    ASSERT_NE(it, merged.end());
    ASSERT_NEAR(it->second, v, 1e-5);
    both_occupied += v == 3.5f;
    mixed += std::abs(v - 1.5f) < 1e-5;  // 3.5 + (-2)
  }
  EXPECT_GT(mixed, 100);
  EXPECT_GT(both_occupied, 100);
}

TEST(MapComposerTest, IncrementalUpdateRebuildsOnlyMovedSubmapsAndEqualsFullRebuild) {
  SubmapOptions so;
  MapComposer composer(CompositionOptions{}, so);
  std::vector<std::shared_ptr<const Submap>> maps;
  for (uint64_t i = 0; i < 4; ++i) maps.push_back(testing::SyntheticSubmap(i, 1, static_cast<unsigned>(i + 1)));
  const auto pose = [](double x, double yaw) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(x, 0.5 * x, 0.0);
    return T;
  };
  for (size_t i = 0; i < maps.size(); ++i) ASSERT_TRUE(composer.SetSubmap(maps[i], pose(3.0 * i, 0.3 * i)).ok());
  EXPECT_EQ(composer.Update().rebuilt, 4);
  // Small pose changes below the thresholds keep the cache; a loop-closure-sized change rebuilds
  // exactly that submap.
  ASSERT_TRUE(composer.SetPose({"rover1", 1}, pose(3.005, 0.3)).ok());
  CompositionStats s = composer.Update();
  EXPECT_EQ(s.rebuilt, 0);
  EXPECT_EQ(s.cached, 4);
  ASSERT_TRUE(composer.SetPose({"rover1", 2}, pose(6.4, 0.65)).ok());
  s = composer.Update();
  EXPECT_EQ(s.rebuilt, 1);
  EXPECT_EQ(s.cached, 3);
  // (Undo the tolerated change so that the full rebuild below uses the cached poses.)
  ASSERT_TRUE(composer.SetPose({"rover1", 1}, pose(3.0, 0.3)).ok());
  EXPECT_EQ(composer.Update().rebuilt, 0);
  const auto incremental = Voxels(*composer.Octree());
  const size_t cloud_incremental = composer.Cloud().size();
  composer.Rebuild();
  const auto full = Voxels(*composer.Octree());
  EXPECT_EQ(cloud_incremental, composer.Cloud().size());
  ASSERT_EQ(incremental.size(), full.size());
  for (const auto& [k, v] : full) ASSERT_NEAR(incremental.at(k), v, 1e-4);
  // The rotated submaps leave no holes: about as many global voxels as source voxels.
  EXPECT_GT(full.size(), 1000u);
  // Removing a submap takes its voxels out.
  composer.RemoveSubmap({"rover1", 0});
  composer.Update();
  EXPECT_LT(Voxels(*composer.Octree()).size(), full.size());
}

TEST(MapComposerTest, OpenSubmapIsMergedButNeverCached) {
  SubmapOptions so;
  MapComposer composer(CompositionOptions{}, so);
  ASSERT_TRUE(composer.SetSubmap(testing::SyntheticSubmap(0, 1), Eigen::Isometry3d::Identity()).ok());
  OpenSubmap open(so, "rover1", 1);
  OccupancyIntegrator integ(0.1, 8.0);
  CameraPoints pts;
  pts.T_local_cam.translation() = Eigen::Vector3d(20, 0, 1);
  pts.p_local = {Eigen::Vector3f(22.05f, 0.05f, 0.05f)};
  pts.p_cam = pts.p_local;
  pts.intensity = {9};
  pts.obstacle = {1};
  open.Integrate(pts, &integ);
  composer.SetOpenSubmap(&open, Eigen::Isometry3d::Identity());
  EXPECT_EQ(composer.Update().cached, 0);
  EXPECT_FLOAT_EQ(composer.LogOdds({22.05, 0.05, 0.05}), 0.85f);
  // It grows: the next Update sees the new data although no pose changed.
  open.Integrate(pts, &integ);
  CompositionStats s = composer.Update();
  EXPECT_EQ(s.cached, 1);
  EXPECT_FLOAT_EQ(composer.LogOdds({22.05, 0.05, 0.05}), 1.7f);
  composer.SetOpenSubmap(nullptr, Eigen::Isometry3d::Identity());
  composer.Update();
  EXPECT_TRUE(std::isnan(composer.LogOdds({22.05, 0.05, 0.05})));
}

TEST(MapComposerTest, MemoryCountsEachSubmapsCachedContribution) {
  MapComposer composer(CompositionOptions{}, SubmapOptions{});
  const size_t empty = composer.memory_bytes();
  const auto s = testing::SyntheticSubmap(0, 3);
  ASSERT_TRUE(composer.SetSubmap(s, Eigen::Isometry3d::Identity()).ok());
  composer.Update();
  // At least the moved copy of its points is cached.
  EXPECT_GE(composer.memory_bytes(), empty + s->points().size() * sizeof(CloudPoint));
  // The submap itself is counted apart: its cloud and every node of its octree.
  EXPECT_GE(s->memory_bytes(), s->points().size() * sizeof(CloudPoint) + s->tree().size() * sizeof(octomap::OcTreeNode));
  EXPECT_EQ(composer.submap_bytes(), s->memory_bytes());
  composer.RemoveSubmap({s->metadata().robot, s->metadata().id});
  composer.Update();
  EXPECT_LT(composer.memory_bytes(), empty + s->points().size() * sizeof(CloudPoint));
  EXPECT_EQ(composer.submap_bytes(), 0u);
}

TEST(MapComposerTest, RejectsMismatchedResolution) {
  MapComposer composer(CompositionOptions{}, SubmapOptions{});
  SubmapMetadata m;
  auto s = std::make_shared<const Submap>(m, std::vector<CloudPoint>{}, std::make_unique<octomap::OcTree>(0.05));
  EXPECT_EQ(composer.SetSubmap(s, Eigen::Isometry3d::Identity()).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace cairn
