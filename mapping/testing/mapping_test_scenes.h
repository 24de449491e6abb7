#pragma once
// Test scenes for mapping: a forward-looking rover camera and depth images rendered from simple
// analytic worlds or from the simulator's terrain, with stereo noise applied in disparity space.

#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include <Eigen/Geometry>

#include "mapping/depth_image.h"

namespace cairn::testing {

// Rectified camera looking along +x of the body, pitched down by `tilt` (camera z forward, x right,
// y down), as the simulated rover's.
inline Eigen::Isometry3d ForwardCameraPose(const Eigen::Vector3d& position, double yaw, double tilt) {
  Eigen::Matrix3d base;
  base.col(0) = -Eigen::Vector3d::UnitY();
  base.col(1) = -Eigen::Vector3d::UnitZ();
  base.col(2) = Eigen::Vector3d::UnitX();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * base *
               Eigen::AngleAxisd(-tilt, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T.translation() = position;
  return T;
}

inline StereoCamera RoverCamera(double scale = 1.0) {
  StereoCamera c;
  c.intrinsics.width = static_cast<int>(std::lround(1024 * scale));
  c.intrinsics.height = static_cast<int>(std::lround(508 * scale));
  c.intrinsics.fx = c.intrinsics.fy = 1080.0 * scale;
  c.intrinsics.cx = (c.intrinsics.width - 1) / 2.0;
  c.intrinsics.cy = (c.intrinsics.height - 1) / 2.0;
  c.baseline = 0.09;
  return c;  // T_body_cam identity: tests pass camera poses as body poses
}

// Depth image by casting every pixel's ray with `hit(origin, dir) -> distance along dir` (< 0 or
// inf: sky). Stereo noise: Gaussian disparity noise of `disparity_sigma_px`, then the 1/16 px
// quantization of the matchers.
inline DepthImage RenderDepth(const StereoCamera& cam, const Eigen::Isometry3d& T_world_cam,
                              const std::function<double(const Eigen::Vector3d&, const Eigen::Vector3d&)>& hit,
                              double disparity_sigma_px = 0.0, unsigned seed = 1) {
  const PinholeRadTan& k = cam.intrinsics;
  DepthImage img;
  img.width = k.width;
  img.height = k.height;
  img.depth.resize(static_cast<size_t>(k.width) * static_cast<size_t>(k.height));
  img.intensity.assign(img.depth.size(), 128);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, disparity_sigma_px);
  const double fb = k.fx * cam.baseline;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d ray((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const Eigen::Vector3d dir = T_world_cam.linear() * ray.normalized();
      const double t = hit(T_world_cam.translation(), dir);
      float& d = img.depth[static_cast<size_t>(v) * static_cast<size_t>(k.width) + static_cast<size_t>(u)];
      if (!(t > 0.0) || !std::isfinite(t)) {
        d = std::numeric_limits<float>::infinity();
        continue;
      }
      const double z = t / ray.norm();
      double disp = fb / z + (disparity_sigma_px > 0.0 ? noise(rng) : 0.0);
      disp = std::round(disp * 16.0) / 16.0;
      d = disp > 0.0 ? static_cast<float>(fb / disp) : std::numeric_limits<float>::infinity();
    }
  }
  return img;
}

}  // namespace cairn::testing
