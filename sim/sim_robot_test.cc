#include "sim/sim_robot.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "sim/terrain.h"
#include "sim/world_options.h"

namespace cairn::sim {
namespace {

// The steepest tilt of a robot's body (angle of its z axis from the vertical) over its trajectory.
double MaxTilt(const SimRobot& robot, double duration) {
  double tilt = 0.0;
  for (double t = 0.0; t <= duration; t += 0.1) {
    const double cz = robot.trajectory.Evaluate(t).T_world_body.linear()(2, 2);
    tilt = std::max(tilt, std::acos(std::clamp(cz, -1.0, 1.0)));
  }
  return tilt;
}

// Two rovers of a team deployed from the lander, as the demo's mission makes them, on the default
// world of several seeds: in each of them a drawn loop crossed the big crater (tilting a rover up
// to 72 deg), and in seed 8 the lander stood inside it.
TEST(SimRobotTest, RoversKeepOffGroundThatTiltsThemMoreThan25Degrees) {
  for (int seed = 1; seed <= 8; ++seed) {
    WorldOptions world;
    world.seed = seed;
    const Terrain terrain = Terrain::Generate(world);
    Deployment deployment;
    deployment.enabled = true;
    deployment.lander = Eigen::Vector2d(world.lander[0], world.lander[1]);
    deployment.lander_ground = terrain.Height(world.lander[0], world.lander[1]);
    for (int index : {0, 2}) {
      const SimRobot rover = MakeRover(terrain, "rover", index, static_cast<uint64_t>(seed), 120.0, 0.1,
                                       world.tag_size, &deployment);
      EXPECT_LT(MaxTilt(rover, 120.0), 25.5 * kDegree) << "seed " << seed << ", rover " << index;
    }
  }
}

// The largest horizontal distance between two robots' positions at equal times.
double LargestGap(const SimRobot& a, const SimRobot& b, double duration) {
  double gap = 0.0;
  for (double t = 0.0; t <= duration; t += 0.5) {
    const Eigen::Vector3d d = a.trajectory.Evaluate(t).T_world_body.translation() -
                              b.trajectory.Evaluate(t).T_world_body.translation();
    gap = std::max(gap, d.head<2>().norm());
  }
  return gap;
}

// The loop is moved only where it has to be: on gentle ground a rover drives the loop its seed
// drew, whatever the ground's shape; on seed 2's default world the same loop crossed the big
// crater, and the rover drives another.
TEST(SimRobotTest, ADrivableLoopIsDrivenAsDrawn) {
  WorldOptions world;
  world.seed = 2;
  world.lander.clear();
  world.crater_density = 0.0;
  world.rock_density = 0.0;
  world.big_crater = false;
  world.relief = 0.0;
  const Terrain level = Terrain::Generate(world);
  world.relief = 0.3;
  const Terrain gentle = Terrain::Generate(world);
  WorldOptions default_world;
  default_world.seed = 2;
  default_world.lander.clear();
  const Terrain rough = Terrain::Generate(default_world);
  const auto rover2 = [&](const Terrain& terrain) {
    return MakeRover(terrain, "rover2", 2, 2, 60.0, 0.1, world.tag_size);
  };
  EXPECT_LT(LargestGap(rover2(level), rover2(gentle), 60.0), 1e-9);
  EXPECT_GT(LargestGap(rover2(level), rover2(rough), 60.0), 1.0);
  EXPECT_LT(MaxTilt(rover2(rough), 60.0), 25.5 * kDegree);
}

}  // namespace
}  // namespace cairn::sim
