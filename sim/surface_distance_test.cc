#include "sim/surface_distance.h"

#include <gtest/gtest.h>

namespace cairn::sim {
namespace {

TEST(SurfaceDistanceTest, TerrainDistanceAboveAndBelowTheSurface) {
  WorldOptions world;
  world.size = 30.0;
  const Terrain terrain = Terrain::Generate(world);
  const SurfaceDistance d(terrain);
  for (const auto& [x, y] : {std::pair{1.0, 2.0}, std::pair{-7.3, 4.4}, std::pair{9.1, -3.7}}) {
    const double h = terrain.Height(x, y);
    EXPECT_LT(d.Distance({x, y, h}, 0.1), 1e-9);
    // Straight above or below: at most the vertical offset, and not much less unless the ground
    // is steep (the normal leans).
    const double up = d.Distance({x, y, h + 0.05}, 0.1);
    EXPECT_LE(up, 0.05 + 1e-9);
    EXPECT_GT(up, 0.05 / std::sqrt(1.0 + terrain.max_slope() * terrain.max_slope()) - 0.011);
    EXPECT_LE(d.Distance({x, y, h - 0.03}, 0.1), 0.03 + 1e-9);
    EXPECT_GT(d.Distance({x, y, h + 1.0}, 0.1), 0.1);
  }
}

TEST(SurfaceDistanceTest, LanderAndRobotBodiesCount) {
  MissionOptions m;
  m.robots = {"rover"};
  m.duration = 2.0;
  m.image_scale = 0.1;
  WorldOptions world;
  world.size = 30.0;
  auto mission = MissionSimulator::Create(world, m);
  ASSERT_TRUE(mission.ok()) << mission.status().ToString();
  const MissionSimulator& sim = **mission;
  ASSERT_FALSE(sim.static_boxes().empty());
  const SurfaceDistance terrain_only(sim.terrain());
  const SurfaceDistance all(sim, 0.5);

  // 5 cm outside the lander's +x face, well above the ground and beside the marker on that face.
  const SimBox& lander = sim.static_boxes().front();
  const Eigen::Vector3d face =
      lander.T_body_box * Eigen::Vector3d(lander.half_extent.x() + 0.05, 0.75 * lander.half_extent.y(), 0.3);
  EXPECT_GT(terrain_only.Distance(face, 0.1), 0.1);
  EXPECT_NEAR(all.Distance(face, 0.1), 0.05, 0.01);
  // 4 cm inside the box, below its top face.
  const Eigen::Vector3d inside = lander.T_body_box * Eigen::Vector3d(0.0, 0.0, lander.half_extent.z() - 0.04);
  EXPECT_NEAR(all.Distance(inside, 0.1), 0.04, 1e-9);

  // The rover's body where it was at t = 1 s (a sampled instant), 2 cm above its highest box.
  const SimRobot& rover = sim.robots().front();
  ASSERT_FALSE(rover.boxes.empty());
  const Eigen::Isometry3d T_world_body = rover.trajectory.Evaluate(1.0).T_world_body;
  const SimBox& body = rover.boxes.front();
  const Eigen::Vector3d top = T_world_body * body.T_body_box * Eigen::Vector3d(0.0, 0.0, body.half_extent.z() + 0.02);
  EXPECT_LE(all.Distance(top, 0.1), 0.02 + 1e-9);
  EXPECT_GT(all.solid_count(), terrain_only.solid_count());
}

}  // namespace
}  // namespace cairn::sim
