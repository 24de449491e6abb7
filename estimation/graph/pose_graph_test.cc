#include "estimation/graph/pose_graph.h"

#include <gtest/gtest.h>

#include "estimation/math/so3.h"

namespace cairn {
namespace {

Pose3 MakePose(double x, double y, double z, double rx, double ry, double rz) {
  return {Eigen::Vector3d(x, y, z), so3::ExpQuaternion(Eigen::Vector3d(rx, ry, rz))};
}

TEST(PoseGraphTest, RobotKeysCarryTheLetterInTheTopByte) {
  EXPECT_EQ(MakeRobotKey('a', 0), 6989586621679009792ULL);
  EXPECT_EQ(RobotOfKey(MakeRobotKey('b', 17)), static_cast<unsigned>('b'));
  EXPECT_EQ(IndexOfKey(MakeRobotKey('b', 17)), 17u);
}

TEST(PoseGraphTest, CostsVanishAtConsistentPosesAndMatchHandComputation) {
  PoseGraph g;
  const Pose3 a = MakePose(1, 2, 3, 0.1, -0.2, 0.3), b = MakePose(-1, 0.5, 2, 0.4, 0.1, -0.7);
  g.SetVertex(0, a);
  g.SetVertex(1, b);
  PoseGraphEdge e;
  e.from = 0;
  e.to = 1;
  e.T_from_to = a.Inverse() * b;
  PoseGraph::SetIsotropicWeights(e);
  g.AddEdge(e);
  EXPECT_NEAR(SeSyncCost(g), 0.0, 1e-20);
  EXPECT_NEAR(GeodesicChi2(g), 0.0, 1e-20);
  // Shift b by 0.1 m along x: translation term only, tau = 1 for unit information.
  g.poses()[1].t.x() += 0.1;
  EXPECT_NEAR(SeSyncCost(g), 0.01, 1e-12);
  EXPECT_NEAR(GeodesicChi2(g), 0.01, 1e-12);
  // Rotate b by 0.2 rad: ||I - Exp||_F^2 = 4 (1 - cos), kappa = 1/2 for unit information.
  g.poses()[1] = b * MakePose(0, 0, 0, 0, 0, 0.2);
  EXPECT_NEAR(SeSyncCost(g), 0.5 * 4.0 * (1.0 - std::cos(0.2)), 1e-12);
  EXPECT_NEAR(GeodesicChi2(g), 0.04, 1e-12);
}

TEST(PoseGraphTest, SpanningTreePrefersOdometryAndFindsComponents) {
  PoseGraph g;
  const Pose3 step = MakePose(1, 0, 0, 0, 0, 0.1);
  for (uint64_t i = 0; i < 4; ++i) {
    PoseGraphEdge e;
    e.from = i;
    e.to = i + 1;
    e.T_from_to = step;
    g.AddEdge(e);
  }
  PoseGraphEdge loop;  // a wrong loop closure must not be used when odometry reaches vertex 4
  loop.from = 0;
  loop.to = 4;
  loop.T_from_to = MakePose(100, 0, 0, 0, 0, 0);
  g.AddEdge(loop);
  PoseGraphEdge other;  // second component
  other.from = 10;
  other.to = 11;
  other.T_from_to = step;
  g.AddEdge(other);
  InitializeFromSpanningTree(g);
  const Pose3 expected = step * step * step * step;
  EXPECT_LT((g.poses()[g.Find(4)].t - expected.t).norm(), 1e-12);
  int count = 0;
  const auto comp = g.Components(&count);
  EXPECT_EQ(count, 2);
  EXPECT_NE(comp[g.Find(0)], comp[g.Find(10)]);
}

}  // namespace
}  // namespace cairn
