#pragma once
// Rendered stereo pairs of a world with man-made structure (configs/worlds/structures.yaml), seen
// by the rover's camera from poses of one's choosing, for the line-segment tests and `cairn bench
// lines`: the terrain (with the structures' blocks), the lander and its tags, without robots.

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/testing/mapping_test_scenes.h"
#include "sim/camera_renderer.h"
#include "sim/mission_simulator.h"
#include "sim/sim_random.h"

namespace cairn::testing {

struct StructureStereoFrame {
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();  // the left camera
  std::vector<uint8_t> left, right;
  std::vector<float> depth;  // the left image's ray-cast z-depth, 0 for sky
};

// The rover camera's pose `i` of `count` along a 3.4 m drive around the north-west corner of the
// lander of structures.yaml (2-4 m from its lit west and north faces and their tags), at the
// camera's height of 1.3 m above the ground, pitched down 25 degrees like the rover's.
inline Eigen::Isometry3d StructureDrivePose(const sim::Terrain& terrain, int i, int count) {
  const double s = count > 1 ? static_cast<double>(i) / (count - 1) : 0.0;
  const double x = 3.0 + 3.0 * s, y = -1.5 + 1.5 * s;
  const double yaw = (-40.0 - 40.0 * s) * M_PI / 180.0;
  return ForwardCameraPose({x, y, terrain.Height(x, y) + 1.3}, yaw, 25.0 * M_PI / 180.0);
}

// Both images of the rectified pair at T_world_cam (the right camera `baseline` along the left's
// x), each with its own sensor noise from `seed`.
inline void RenderStructureFrame(const sim::MissionSimulator& sim, const StereoCamera& cam,
                                 const Eigen::Isometry3d& T_world_cam, uint64_t seed,
                                 StructureStereoFrame* frame) {
  sim::RenderScene scene;
  scene.terrain = &sim.terrain();
  scene.sun_direction = sim.sun_direction();
  scene.boxes = sim.static_boxes();
  scene.markers = sim.landmarks();
  frame->T_world_cam = T_world_cam;
  const sim::RenderOptions options;
  sim::CameraRenderer::Render(scene, cam.intrinsics, T_world_cam, options, sim::SimRandom::Mix(2 * seed),
                              &frame->left, &frame->depth);
  sim::CameraRenderer::Render(scene, cam.intrinsics,
                              T_world_cam * Eigen::Translation3d(cam.baseline, 0.0, 0.0), options,
                              sim::SimRandom::Mix(2 * seed + 1), &frame->right, nullptr);
}

}  // namespace cairn::testing
