#include "estimation/graph/topology_builder.h"

#include <gtest/gtest.h>

#include "estimation/math/so3.h"

namespace cairn {
namespace {

TEST(TopologyBuilderTest, FilterTopologyEmitsFrameSwitchesAndFilterEstimates) {
  TopologyBuilder b(TopologyBuilder::Topology::kFilter, 'b');
  EXPECT_TRUE(b.Start(false, Matrix6d::Identity()).empty());  // not the own robot: no prior
  uint64_t x = 0;
  auto v = b.PoseEstimate(Pose3(), Matrix6d::Identity() * 0.01, &x);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_EQ(v[0].kind, FactorKind::kFilterEstimate);
  EXPECT_EQ(v[0].a, VariableKey(VariableKind::kSubmap, 'b', 0));
  EXPECT_EQ(v[0].b, x);
  EXPECT_NEAR(v[0].information(0, 0), 100.0, 1e-9);
  auto w = b.FrameSwitch(Pose3(), Matrix6d::Identity());
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].kind, FactorKind::kFrameSwitch);
  EXPECT_EQ(w[0].b, VariableKey(VariableKind::kSubmap, 'b', 1));
}

TEST(TopologyBuilderTest, SequentialOdometryUsesEq48AndClampedEq49) {
  TopologyBuilder b(TopologyBuilder::Topology::kSequential, 'a');
  ASSERT_EQ(b.Start(true, Matrix6d::Identity()).size(), 1u);
  const Pose3 x1{Eigen::Vector3d(1, 0, 0), so3::ExpQuaternion(Eigen::Vector3d(0, 0, 0.3))};
  const Pose3 x2{Eigen::Vector3d(2, 1, 0), so3::ExpQuaternion(Eigen::Vector3d(0, 0, 0.5))};
  auto u1 = b.PoseEstimate(x1, Matrix6d::Identity() * 0.04, nullptr);
  ASSERT_EQ(u1.size(), 1u);
  EXPECT_EQ(u1[0].kind, FactorKind::kOdometry);
  EXPECT_NEAR(u1[0].information(0, 0), 25.0, 1e-6);  // Sigma_x1 - Sigma_x0 (0)
  // The filter got more certain (e.g. after a keyframe): the difference is clamped to 1e-10.
  auto u2 = b.PoseEstimate(x2, Matrix6d::Identity() * 0.01, nullptr);
  ASSERT_EQ(u2.size(), 1u);
  EXPECT_NEAR(u2[0].information(0, 0), 1e10, 1e2);
  const Pose3 expected = x1.Inverse() * x2;  // eq. 4.8
  EXPECT_LT((u2[0].z.t - expected.t).norm(), 1e-12);
  EXPECT_LT(u2[0].z.q.angularDistance(expected.q), 1e-12);
  // Submap origins are robot poses in this topology.
  b.FrameSwitch(Pose3(), Matrix6d::Identity() * 0.01);
  EXPECT_EQ(KindOfKey(b.SubmapKey(1)), VariableKind::kRobotPose);
}

}  // namespace
}  // namespace cairn
