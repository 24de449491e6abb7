#include "mapping/local_mapper.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "mapping/testing/mapping_test_scenes.h"

namespace cairn {
namespace {

struct NoSwitches : FrameSwitchRequesterInterface {
  void RequestFrameSwitch(const FrameSwitchRequest&) override {}
};

struct WallMap {
  size_t cloud_points = 0;
  int64_t occupied = 0, free = 0;
  int64_t unmapped = 0;
};

// One image of a wall `distance` ahead, with depth.max_map_error `max_map_error`.
WallMap MapWall(double distance, double max_map_error) {
  const StereoCamera cam = testing::RoverCamera(0.25);
  MappingOptions o;
  o.depth.max_depth_error = 1.0;
  o.depth.max_map_error = max_map_error;
  NoSwitches requester;
  LocalMapper mapper(o, cam, "rover1", &requester);
  const Eigen::Isometry3d T = testing::ForwardCameraPose(Eigen::Vector3d(0.0, 0.0, 1.0), 0.0, 0.0);
  const auto wall = [distance](const Eigen::Vector3d& p, const Eigen::Vector3d& d) {
    return d.x() > 0.0 ? (distance - p.x()) / d.x() : std::numeric_limits<double>::infinity();
  };
  MappingPose pose;
  pose.frame_id = 1;
  pose.T_local_body = T;
  EXPECT_TRUE(mapper.Process(testing::RenderDepth(cam, T, wall), pose).ok());
  WallMap m;
  m.unmapped = mapper.stats().unmapped_points;
  m.cloud_points = mapper.open_submap().cloud().size();
  const auto submap = mapper.FinishOpenSubmap();
  if (submap == nullptr) return m;
  for (auto it = submap->tree().begin_leafs(); it != submap->tree().end_leafs(); ++it) {
    (submap->tree().isNodeOccupied(*it) ? m.occupied : m.free) += 1;
  }
  return m;
}

TEST(LocalMapperTest, PointsBeyondTheMapErrorOnlyClearFreeSpace) {
  // Eq. 5.2c at f 270 px, b 0.09 m: 0.065 m at 1.5 m, 0.26 m at 3 m.
  const WallMap near = MapWall(1.5, 0.1), far = MapWall(3.0, 0.1), far_all = MapWall(3.0, 0.0);
  EXPECT_EQ(near.unmapped, 0);
  EXPECT_GT(near.occupied, 100);
  EXPECT_GT(near.cloud_points, 100u);
  // The far wall's points stay out of the cloud and the occupied voxels, but their rays still
  // clear the space in front of the wall.
  EXPECT_GT(far.unmapped, 1000);
  EXPECT_EQ(far.cloud_points, 0u);
  EXPECT_EQ(far.occupied, 0);
  EXPECT_GT(far.free, far_all.free / 2);
  // 0: every point is mapped.
  EXPECT_EQ(far_all.unmapped, 0);
  EXPECT_GT(far_all.occupied, 100);
}

}  // namespace
}  // namespace cairn
