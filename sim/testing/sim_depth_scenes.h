#pragma once
// Depth images of the simulator's terrain with stereo noise, for mapping tests and `cairn bench map`.

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "mapping/testing/mapping_test_scenes.h"
#include "sim/camera_renderer.h"
#include "sim/terrain.h"

namespace cairn::testing {

// The terrain seen from T_world_cam: rendered z-depth (sky: beyond range), Gaussian disparity
// noise of `disparity_sigma_px` and the matchers' 1/16 px quantization, and the gray image.
inline DepthImage RenderSimulatedDepth(const sim::Terrain& terrain, const StereoCamera& cam,
                                       const Eigen::Isometry3d& T_world_cam, unsigned seed,
                                       double disparity_sigma_px) {
  sim::RenderScene scene;
  scene.terrain = &terrain;
  std::vector<uint8_t> gray;
  std::vector<float> depth;
  sim::CameraRenderer::Render(scene, cam.intrinsics, T_world_cam, sim::RenderOptions{}, seed, &gray, &depth);
  DepthImage img;
  img.width = cam.intrinsics.width;
  img.height = cam.intrinsics.height;
  img.intensity = std::move(gray);
  img.depth.resize(depth.size());
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, disparity_sigma_px);
  const double fb = cam.intrinsics.fx * cam.baseline;
  for (size_t i = 0; i < depth.size(); ++i) {
    const double d = depth[i] > 0.0f ? std::round((fb / depth[i] + noise(rng)) * 16.0) / 16.0 : 0.0;
    img.depth[i] = d > 0.0 ? static_cast<float>(fb / d) : std::numeric_limits<float>::infinity();
  }
  return img;
}

}  // namespace cairn::testing
