#include "mapping/submap.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

CameraPoints OnePoint(float x) {
  CameraPoints pts;
  pts.time = Timestamp::FromSeconds(static_cast<double>(x));
  pts.p_local = {Eigen::Vector3f(x, 0.05f, 0.05f)};
  pts.p_cam = pts.p_local;
  pts.intensity = {9};
  pts.obstacle = {1};
  return pts;
}

TEST(OpenSubmapTest, RestartBeginsAnEmptySubmapUnderTheNewId) {
  SubmapOptions so;
  OpenSubmap open(so, "rover1", 3);
  OccupancyIntegrator integ(0.1, 8.0);
  open.Integrate(OnePoint(2.05f), &integ);
  open.AddDistance(1.5);
  const auto first = open.Finish();
  open.Restart(4);
  EXPECT_EQ(open.metadata().id, 4u);
  EXPECT_EQ(open.metadata().robot, "rover1");
  EXPECT_EQ(open.metadata().images, 0u);
  EXPECT_EQ(open.metadata().distance, 0.0);
  EXPECT_EQ(open.cloud().size(), 0u);
  EXPECT_EQ(open.tree().size(), 0u);

  open.Integrate(OnePoint(5.05f), &integ);
  const auto second = open.Finish();
  ASSERT_EQ(second->points().size(), 1u);
  EXPECT_NEAR(second->points()[0].p.x(), 5.05f, 0.05f);
  EXPECT_EQ(second->metadata().id, 4u);
  EXPECT_EQ(second->metadata().images, 1u);
  EXPECT_EQ(second->metadata().start, OnePoint(5.05f).time);
  // The finished submap is untouched by what came after.
  ASSERT_EQ(first->points().size(), 1u);
  EXPECT_NEAR(first->points()[0].p.x(), 2.05f, 0.05f);
  EXPECT_EQ(first->metadata().id, 3u);
  EXPECT_EQ(first->metadata().distance, 1.5);
}

TEST(OpenSubmapTest, RestartOfAnUnusedSubmapOnlyRenamesIt) {
  OpenSubmap open(SubmapOptions{}, "rover1", 0);
  open.Restart(9);
  EXPECT_EQ(open.metadata().id, 9u);
  OccupancyIntegrator integ(0.1, 8.0);
  open.Integrate(OnePoint(1.05f), &integ);
  EXPECT_EQ(open.Finish()->metadata().id, 9u);
}

}  // namespace
}  // namespace cairn
