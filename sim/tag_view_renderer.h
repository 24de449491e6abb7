#pragma once
// One tag36h11 marker seen by a camera at a known pose, rendered by the simulator's camera model
// (ray-cast terrain behind it, Lambertian shading, the sensor's read and shot noise) into a window
// of the image just large enough to hold it: what an error table is built from
// (`cairn detect build-lut`) and checked against.
//
// The camera hangs high above the middle of a generated world looking down, so that every tag in
// front of it (up to 25 m away) has terrain behind it, never sky. The sun stands behind the camera,
// lighting the tag as the cosine of its viewing angle.

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "common/status.h"
#include "hal/calibration.h"
#include "sim/camera_renderer.h"
#include "sim/terrain.h"

namespace cairn::sim {

struct TagView {
  int x0 = 0, y0 = 0;  // the window's top-left pixel in the full image (even: decimation keeps its grid)
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;  // row-major, width x height
  // The tag's corners in the full image (px, pixel centres at whole numbers), in AprilTag's
  // detection order (tag_pose_estimator.h).
  std::array<Eigen::Vector2d, 4> corners;
};

class TagViewRenderer {
 public:
  TagViewRenderer(const Terrain& terrain, const PinholeRadTan& camera, RenderOptions options = {});

  // `T_cam_tag` in AprilTag's frame; the margin of background kept around the tag's outer white
  // ring is `margin` px. Fails when the tag is behind the camera or not wholly inside the image.
  Expected<TagView> Render(int id, double tag_size, const Eigen::Isometry3d& T_cam_tag, uint64_t noise_seed,
                           int margin = 24) const;

 private:
  const Terrain& terrain_;
  PinholeRadTan camera_;
  RenderOptions options_;
  Eigen::Isometry3d T_world_cam_;
};

}  // namespace cairn::sim
