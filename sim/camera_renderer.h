#pragma once
// Renders one rectified pinhole image of the world by ray casting: the terrain through its
// max-mipmap, robots' bodies (boxes) and markers (planar squares), Lambertian sun shading plus an
// ambient term, and photometric noise (read noise plus shot noise) from a seeded generator.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "hal/calibration.h"
#include "sim/sim_robot.h"
#include "sim/terrain.h"

namespace cairn::sim {

// Everything visible at one instant, in the world frame.
struct RenderScene {
  const Terrain* terrain = nullptr;
  Eigen::Vector3d sun_direction = Eigen::Vector3d::UnitZ();  // unit, pointing to the sun
  std::vector<SimBox> boxes;       // T_body_box holds T_world_box here
  std::vector<SimMarker> markers;  // T_body_marker holds T_world_marker here

  // Adds a robot's geometry at pose T_world_body.
  void AddRobot(const SimRobot& robot, const Eigen::Isometry3d& T_world_body);
};

struct RenderOptions {
  double gain = 1.6;          // DN per unit radiance / 255 at exposure 1
  double exposure = 1.0;      // relative exposure (scales the signal)
  double ambient = 0.05;      // sky and multi-bounce light, fraction of direct sun
  double read_noise = 1.5;    // DN, one sigma
  double shot_noise = 0.15;   // DN per DN of signal (variance)
  double max_range = 150.0;   // m
};

class CameraRenderer {
 public:
  // Renders 8-bit grey values (row-major, width * height) and, when `depth` is not null, the
  // z-depth of every pixel in metres (0 where the ray reaches the sky).
  static void Render(const RenderScene& scene, const PinholeRadTan& camera,
                     const Eigen::Isometry3d& T_world_cam, const RenderOptions& options,
                     uint64_t noise_seed, std::vector<uint8_t>* image, std::vector<float>* depth);
  // The two halves of Render, so that motion blur can average noise-free signals over the
  // exposure before the sensor adds its noise once.
  static void RenderSignal(const RenderScene& scene, const PinholeRadTan& camera,
                           const Eigen::Isometry3d& T_world_cam, const RenderOptions& options,
                           std::vector<float>* signal, std::vector<float>* depth);
  static void ApplyNoise(const std::vector<float>& signal, int width, const RenderOptions& options,
                         uint64_t noise_seed, std::vector<uint8_t>* image);
};

}  // namespace cairn::sim
