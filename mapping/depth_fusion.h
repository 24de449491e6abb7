#pragma once
// Temporal fusion of consecutive dense depth images of one camera. Stereo depth noise is mostly
// independent between images (sub-pixel matching noise), so averaging a surface over several
// images shrinks it where a single image's eq. 5.2c error spreads a surface over many voxels.
// The previous fused image (depth and variance per pixel, in its camera) is warped into the new
// camera: each new pixel's point is moved into the previous camera, the fused depth there is
// interpolated and moved back, and the two are averaged by inverse variance when they agree
// within a few sigmas; otherwise the new measurement starts over (occlusion, disocclusion, moving
// objects). Only relative camera poses enter, so local frame switches need just Rebase().
// Buffers are allocated at construction; not thread safe.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/depth_image.h"
#include "mapping/mapping_options.h"
#include "stereo/stereo_error_model.h"

namespace cairn {

struct DepthFusionStats {
  int64_t measured = 0;  // pixels of the last image with a finite depth
  int64_t fused = 0;     // ...of which agreed with the warped fused image
};

class DepthFusion {
 public:
  DepthFusion(const DepthFusionOptions& options, const StereoCamera& camera, const StereoErrorModel& model);

  // Fuses `image`, seen from T_local_cam, with the images before it. The result is fused() and
  // depth_error(), valid until the next call.
  Status Fuse(const DepthImage& image, const Eigen::Isometry3d& T_local_cam);
  // The local frame changed; T_old_new is the new frame's pose in the old one.
  void Rebase(const Eigen::Isometry3d& T_old_new);
  // Forgets the images so far (the relative pose to the next image is unknown).
  void Reset() { has_previous_ = false; }

  // The last fused image: depth where the input had a finite one, its NaN and +inf elsewhere.
  const DepthImage& fused() const { return out_; }
  // Standard deviation of each pixel's fused depth (m); +inf where fused() has no finite depth.
  std::span<const float> depth_error() const { return out_sigma_; }
  const DepthFusionStats& stats() const { return stats_; }

 private:
  // Fused depth and sigma of the previous image at (u, v) (pixels); false when none.
  bool Sample(float u, float v, float* depth, float* sigma) const;

  DepthFusionOptions options_;
  PinholeRadTan intrinsics_;
  float c_;  // eq. 5.2c: sigma_z = c z^2
  std::vector<float> ray_x_;  // x / z of each column's ray
  bool has_previous_ = false;
  Eigen::Isometry3d T_local_previous_ = Eigen::Isometry3d::Identity();
  std::vector<float> previous_depth_, previous_sigma_;
  DepthImage out_;
  std::vector<float> out_sigma_;
  DepthFusionStats stats_;
};

}  // namespace cairn
