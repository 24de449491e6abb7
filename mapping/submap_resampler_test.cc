#include "mapping/submap_resampler.h"

#include <cmath>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/mapping_options.h"
#include "mapping/occupancy_integrator.h"

namespace cairn {
namespace {

// A submap of flat ground at height h: one occupied layer of 0.1 m voxels (three hits each), two
// free layers above it, and cloud points on the surface (0.05 m apart).
struct FlatSubmap {
  std::unique_ptr<octomap::OcTree> tree = MakeOccupancyTree(SubmapOptions{});
  std::vector<CloudPoint> points;
  explicit FlatSubmap(double h) {
    for (int i = -10; i < 10; ++i) {
      for (int j = -10; j < 10; ++j) {
        const double x = 0.1 * i + 0.05, y = 0.1 * j + 0.05;
        for (int k = 0; k < 3; ++k) tree->updateNode(octomap::point3d(x, y, h), true);
        for (int k = 0; k < 3; ++k) tree->updateNode(octomap::point3d(x, y, h + 0.1), false);
        for (int k = 0; k < 3; ++k) tree->updateNode(octomap::point3d(x, y, h + 0.2), false);
      }
    }
    for (int i = -20; i < 20; ++i) {
      for (int j = -20; j < 20; ++j) {
        CloudPoint c;
        c.p = Eigen::Vector3f(static_cast<float>(0.05 * i + 0.025), static_cast<float>(0.05 * j + 0.025),
                              static_cast<float>(h));
        points.push_back(c);
      }
    }
  }
};

Eigen::Isometry3d Pose(double yaw, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = t;
  return T;
}

// Global voxel layers (z index at 0.1 m) holding occupied and free output.
void Layers(const std::vector<std::pair<uint64_t, float>>& occupancy, std::set<int>* occupied, std::set<int>* free) {
  for (const auto& [key, value] : occupancy) (value > 0.0f ? occupied : free)->insert(VoxelKey::Unpack(key).z());
}

// The ground at 0.09 m, moved 0.27 m down, lies at -0.18 m, in the layer [-0.2, -0.1). Its voxel's
// centre (0.05 m) would land at -0.22 m, one layer too low: a whole submap half a voxel off.
TEST(SubmapResamplerTest, OccupiedVoxelsFollowTheirPointsOffTheGrid) {
  const FlatSubmap s(0.09);
  SubmapResampler resampler;
  std::vector<CloudPoint> cloud;
  std::vector<std::pair<uint64_t, float>> occupancy;
  for (const double yaw : {0.0, 0.5}) {
    resampler.Resample(*s.tree, s.points, Pose(yaw, {0.37, -0.21, -0.27}), &cloud, &occupancy);
    std::set<int> occupied, free;
    Layers(occupancy, &occupied, &free);
    EXPECT_EQ(occupied, std::set<int>({-2})) << "yaw " << yaw;
    // Free space has no points to follow: its voxels move from their centres (0.15 and 0.25 m,
    // to -0.12 and -0.02 m). The lower one lands on the surface, which it must not dilute.
    EXPECT_EQ(free, std::set<int>({-1})) << "yaw " << yaw;
    for (const auto& [key, value] : occupancy) {
      if (value > 0.0f) {
        EXPECT_NEAR(value, 3 * 0.85f, 0.03f);
      }
    }
    ASSERT_EQ(cloud.size(), s.points.size());
    EXPECT_NEAR(cloud.front().p.z(), 0.09 - 0.27, 1e-6);
  }
}

TEST(SubmapResamplerTest, OccupiedVoxelsWithoutPointsMoveFromTheirCentres) {
  const FlatSubmap s(0.09);
  SubmapResampler resampler;
  std::vector<CloudPoint> cloud;
  std::vector<std::pair<uint64_t, float>> occupancy;
  resampler.Resample(*s.tree, {}, Pose(0.5, {0.37, -0.21, -0.27}), &cloud, &occupancy);
  std::set<int> occupied, free;
  Layers(occupancy, &occupied, &free);
  EXPECT_EQ(occupied, std::set<int>({-3}));
}

TEST(SubmapResamplerTest, GridAlignedPosesMoveEveryVoxelExactly) {
  const FlatSubmap s(0.09);
  SubmapResampler resampler;
  std::vector<CloudPoint> cloud;
  std::vector<std::pair<uint64_t, float>> occupancy;
  resampler.Resample(*s.tree, s.points, Pose(0.0, {0.3, -0.2, -0.3}), &cloud, &occupancy);
  std::set<int> occupied, free;
  Layers(occupancy, &occupied, &free);
  EXPECT_EQ(occupied, std::set<int>({-3}));
  EXPECT_EQ(free, std::set<int>({-2, -1}));
  size_t n_occupied = 0;
  for (const auto& [key, value] : occupancy) n_occupied += value > 0.0f;
  EXPECT_EQ(n_occupied, 400u);
}

}  // namespace
}  // namespace cairn
