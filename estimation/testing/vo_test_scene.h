#pragma once
// Test scene for the visual odometry: a closed box room whose walls carry a smooth random
// texture, rendered by ray casting into a rectified stereo pair at any camera pose. The texture
// is band-limited (interpolated value noise with cells of several pixels) so that sampling at
// pixel centres is faithful and sub-pixel tracking has a well-defined answer.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "estimation/vo/vo_types.h"

namespace cairn::testing {

struct RenderedPair {
  std::vector<uint8_t> left, right;
};

class VoTestScene {
 public:
  // Room [-hx, hx] x [-hy, hy] x [z0, z1] in the world frame (camera looks along +z at identity).
  VoTestScene(const RectifiedStereoCamera& camera, uint64_t seed, double hx = 2.0, double hy = 1.2,
              double z0 = -3.0, double z1 = 3.5);

  // Pair seen by the left camera at T_world_cam (the right one is baseline along +x).
  RenderedPair Render(const Eigen::Isometry3d& T_world_cam) const;

  static RectifiedStereoCamera EurocLikeCamera();

 private:
  void RenderImage(const Eigen::Isometry3d& T_world_cam, std::vector<uint8_t>* out) const;
  double Texture(int wall, double a, double b) const;
  double Noise(int wall, int octave, double a, double b) const;

  RectifiedStereoCamera camera_;
  uint64_t seed_;
  double hx_, hy_, z0_, z1_;
};

}  // namespace cairn::testing
