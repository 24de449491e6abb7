#include "mapping/rolling_obstacle_map.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace cairn {
namespace {

ObstacleCell Cell(float x, float y, float t) {
  ObstacleCell c;
  c.x = x;
  c.y = y;
  c.traversability = t;
  c.obstacle = t > 1.0f;
  return c;
}

TEST(RollingObstacleMapTest, LowPassBlendsObservations) {
  RollingMapOptions o;
  o.low_pass = 0.25;
  RollingObstacleMap map(o);
  map.Recenter({0, 0});
  EXPECT_TRUE(std::isnan(map.At({1.02, 1.02})));
  map.Integrate({Cell(1.025f, 1.025f, 2.0f)});
  EXPECT_FLOAT_EQ(map.At({1.02, 1.03}), 2.0f);  // first observation taken as is
  map.Integrate({Cell(1.025f, 1.025f, 0.0f)});
  EXPECT_FLOAT_EQ(map.At({1.02, 1.03}), 1.5f);  // 0.75 * 2 + 0.25 * 0
}

TEST(RollingObstacleMapTest, ScrollingKeepsCellsInsideAndForgetsCellsThatLeave) {
  RollingMapOptions o;
  o.cells = 100;  // 5 m
  RollingObstacleMap map(o);
  map.Recenter({0, 0});
  map.Integrate({Cell(1.0f, 0.0f, 0.5f), Cell(-2.4f, 0.0f, 3.0f)});
  map.Recenter({1.0, 0.0});  // window now x in [-1.5, 3.5)
  EXPECT_FLOAT_EQ(map.At({1.0, 0.0}), 0.5f);
  EXPECT_TRUE(std::isnan(map.At({-2.4, 0.0})));
  // The slot of the forgotten cell is reused for a new one that must start unknown.
  EXPECT_TRUE(std::isnan(map.At({2.6, 0.0})));
  map.Recenter({1.0, 0.0});
  const GridMap g = map.Snapshot();
  EXPECT_EQ(g.width, 100);
  EXPECT_NEAR(g.origin_x, -1.5, 1e-9);
  const int ix = static_cast<int>(std::floor((1.0 - g.origin_x) / g.resolution));
  const int iy = static_cast<int>(std::floor((0.0 - g.origin_y) / g.resolution));
  EXPECT_FLOAT_EQ(g.at(ix, iy), 0.5f);
  // Far jump: everything forgotten.
  map.Recenter({100.0, 0.0});
  EXPECT_TRUE(std::isnan(map.At({1.0, 0.0})));
}

TEST(RollingObstacleMapTest, RebaseReexpressesTheMapInTheNewFrame) {
  RollingObstacleMap map(RollingMapOptions{});
  map.Recenter({2.0, 0.0});
  map.Integrate({Cell(3.025f, 0.025f, 4.0f)});
  // New frame at (2, 0) turned by 90 degrees: old (3, 0) is new (0, -1).
  Eigen::Isometry3d T_old_new = Eigen::Isometry3d::Identity();
  T_old_new.linear() = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_old_new.translation() = Eigen::Vector3d(2.0, 0.0, 0.0);
  map.Rebase(T_old_new, {0.0, 0.0});
  EXPECT_FLOAT_EQ(map.At({0.01, -1.01}), 4.0f);
  EXPECT_TRUE(std::isnan(map.At({3.01, 0.01})));
}

}  // namespace
}  // namespace cairn
