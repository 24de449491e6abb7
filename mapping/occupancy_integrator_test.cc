#include "mapping/occupancy_integrator.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace cairn {
namespace {

CameraPoints PointsAt(const Eigen::Vector3d& origin, const std::vector<Eigen::Vector3f>& p) {
  CameraPoints pts;
  pts.T_local_cam.translation() = origin;
  pts.p_local = p;
  pts.p_cam = p;
  pts.obstacle.assign(p.size(), 0);
  pts.intensity.assign(p.size(), 0);
  return pts;
}

float LogOdds(const octomap::OcTree& t, double x, double y, double z) {
  const octomap::OcTreeNode* n = t.search(x, y, z);
  return n == nullptr ? NAN : n->getLogOdds();
}

TEST(OccupancyIntegratorTest, TreeUsesTheThesisLogOddsAndClamping) {
  auto tree = MakeOccupancyTree(SubmapOptions{});
  EXPECT_NEAR(tree->getProbHitLog(), 0.85, 1e-6);
  EXPECT_NEAR(tree->getProbMissLog(), -0.4, 1e-6);
  EXPECT_NEAR(tree->getClampingThresMinLog(), -2.0, 1e-6);
  EXPECT_NEAR(tree->getClampingThresMaxLog(), 3.5, 1e-6);
  EXPECT_DOUBLE_EQ(tree->getResolution(), 0.1);
}

// Many points in one voxel and rays crossing each other's endpoints: one update per voxel per
// image, occupied wins.
TEST(OccupancyIntegratorTest, EachVoxelUpdatedAtMostOncePerImageOccupiedPreferred) {
  auto tree = MakeOccupancyTree(SubmapOptions{});
  OccupancyIntegrator integ(0.1, 6.0);
  // Ten points in the voxel around (2.05, 0.05, 0.05); one point beyond it on the same line, whose
  // ray passes through that occupied voxel; one point in the voxel at (1.05, ...), which the far
  // ray also crosses.
  std::vector<Eigen::Vector3f> p;
  for (int i = 0; i < 10; ++i) p.emplace_back(2.01f + 0.008f * i, 0.05f, 0.05f);
  p.emplace_back(3.05f, 0.05f, 0.05f);
  p.emplace_back(1.05f, 0.05f, 0.05f);
  const OccupancyUpdateStats s = integ.Integrate(PointsAt({0.05, 0.05, 0.05}, p), tree.get());
  EXPECT_EQ(s.occupied, 3);
  EXPECT_FLOAT_EQ(LogOdds(*tree, 2.05, 0.05, 0.05), 0.85f);  // once, not ten times, and not free
  EXPECT_FLOAT_EQ(LogOdds(*tree, 1.05, 0.05, 0.05), 0.85f);
  EXPECT_FLOAT_EQ(LogOdds(*tree, 3.05, 0.05, 0.05), 0.85f);
  EXPECT_FLOAT_EQ(LogOdds(*tree, 1.55, 0.05, 0.05), -0.4f);  // crossed by three rays, updated once
  // A second image adds once more; clamping bounds repeated updates.
  for (int k = 0; k < 10; ++k) integ.Integrate(PointsAt({0.05, 0.05, 0.05}, p), tree.get());
  EXPECT_FLOAT_EQ(LogOdds(*tree, 2.05, 0.05, 0.05), 3.5f);
  EXPECT_FLOAT_EQ(LogOdds(*tree, 1.55, 0.05, 0.05), -2.0f);
}

// Same result as OctoMap's own insertPointCloud with discretization, voxel for voxel.
TEST(OccupancyIntegratorTest, MatchesOctomapInsertPointCloudDiscretized) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Eigen::Vector3f> p;
  octomap::Pointcloud cloud;
  const Eigen::Vector3d origin(0.33, -0.21, 1.27);
  for (int i = 0; i < 20000; ++i) {
    // A bumpy ground patch in front of the sensor.
    const float x = 1.0f + 2.0f * (u(rng) + 1.0f), y = 2.0f * u(rng);
    const float z = 0.1f * std::sin(3.0f * x) * std::cos(2.0f * y) + 0.02f * u(rng);
    p.emplace_back(x, y, z);
    cloud.push_back(x, y, z);
  }
  auto ours = MakeOccupancyTree(SubmapOptions{});
  auto theirs = MakeOccupancyTree(SubmapOptions{});
  OccupancyIntegrator integ(0.1, 6.0);
  for (int k = 0; k < 2; ++k) {
    integ.Integrate(PointsAt(origin, p), ours.get());
    theirs->insertPointCloud(cloud, octomap::point3d(0.33f, -0.21f, 1.27f), -1.0, false, true);
  }
  // insertPointCloud (not lazy) prunes as it goes; compare leaves of equally pruned trees.
  ours->updateInnerOccupancy();
  ours->prune();
  size_t leaves = 0;
  for (auto it = theirs->begin_leafs(); it != theirs->end_leafs(); ++it) {
    const octomap::OcTreeNode* n = ours->search(it.getKey());
    ASSERT_NE(n, nullptr) << it.getCoordinate();
    ASSERT_FLOAT_EQ(n->getLogOdds(), it->getLogOdds()) << it.getCoordinate();
    ++leaves;
  }
  EXPECT_EQ(ours->getNumLeafNodes(), theirs->getNumLeafNodes());
  EXPECT_GT(leaves, 1000u);
}

// The cloud's cells give the same tree as the points themselves, including points on the faces of
// cloud cells (p * 20 an integer in float, where float rounding may have moved them) and points
// whose float product rounds onto a face from below.
TEST(OccupancyIntegratorTest, CellsOfTheCloudGiveTheSameTreeAsThePoints) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Eigen::Vector3f> p;
  for (int i = 0; i < 30000; ++i) {
    const float x = 1.0f + 2.0f * (u(rng) + 1.0f), y = 2.0f * u(rng);
    p.emplace_back(x, y, 0.1f * std::sin(3.0f * x) + 0.02f * u(rng));
  }
  // On faces: multiples of 0.05 and their float neighbours below (some of which round up onto
  // the face when scaled).
  for (int k = -40; k < 40; ++k) {
    const float f = static_cast<float>(k) * 0.05f;
    for (const float c : {f, std::nextafter(f, -1e9f), std::nextafter(std::nextafter(f, -1e9f), -1e9f)}) {
      p.emplace_back(c, 0.5f, 0.3f);
      p.emplace_back(2.0f, c, 0.3f);
      p.emplace_back(2.0f, 0.5f, c);
    }
  }
  const CameraPoints pts = PointsAt({0.33, -0.21, 1.27}, p);
  VoxelCloud cloud(0.05);
  VoxelCloud::Cells cells;
  cloud.AddBatch(pts.p_local, pts.intensity, pts.obstacle, &cells);
  EXPECT_FALSE(cells.on_face.empty());
  auto a = MakeOccupancyTree(SubmapOptions{}), b = MakeOccupancyTree(SubmapOptions{});
  OccupancyIntegrator ia(0.1, 6.0), ib(0.1, 6.0);
  const OccupancyUpdateStats sa = ia.IntegrateCells(pts, cells, cloud.inv_resolution(), a.get());
  const OccupancyUpdateStats sb = ib.Integrate(pts, b.get());
  EXPECT_EQ(sa.occupied, sb.occupied);
  EXPECT_EQ(sa.free, sb.free);
  EXPECT_EQ(sa.rays, sb.rays);
  size_t leaves = 0;
  for (auto it = b->begin_leafs(); it != b->end_leafs(); ++it, ++leaves) {
    const octomap::OcTreeNode* n = a->search(it.getKey());
    ASSERT_NE(n, nullptr) << it.getCoordinate();
    ASSERT_EQ(n->getLogOdds(), it->getLogOdds()) << it.getCoordinate();
  }
  EXPECT_EQ(a->getNumLeafNodes(), b->getNumLeafNodes());
  EXPECT_GT(leaves, 1000u);
  // Another cloud resolution: the integrator takes the points themselves.
  VoxelCloud coarse(0.07);
  VoxelCloud::Cells coarse_cells;
  coarse.AddBatch(pts.p_local, pts.intensity, pts.obstacle, &coarse_cells);
  auto c = MakeOccupancyTree(SubmapOptions{});
  OccupancyIntegrator ic(0.1, 6.0);
  EXPECT_EQ(ic.IntegrateCells(pts, coarse_cells, coarse.inv_resolution(), c.get()).occupied, sb.occupied);
  EXPECT_EQ(c->getNumLeafNodes(), b->getNumLeafNodes());
}

}  // namespace
}  // namespace cairn
