#include "mapping/depth_projector.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace cairn {

DepthProjector::DepthProjector(const DepthPointOptions& options, const StereoCamera& camera)
    : options_(options),
      camera_(camera),
      model_(camera.intrinsics.fx, camera.baseline, options.pixel_error_px),
      range_(std::min(options.max_depth, model_.MaxDepthForError(options.max_depth_error))) {}

Status DepthProjector::Project(const DepthImage& image, const Eigen::Isometry3d& T_local_body, CameraPoints* out,
                               std::span<const float> depth_error) const {
  const PinholeRadTan& k = camera_.intrinsics;
  if (image.width != k.width || image.height != k.height) {
    return InvalidArgumentError("depth image " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                                " does not match camera " + std::to_string(k.width) + "x" + std::to_string(k.height));
  }
  if (image.depth.size() != static_cast<size_t>(image.width) * static_cast<size_t>(image.height) ||
      (!image.intensity.empty() && image.intensity.size() != image.depth.size())) {
    return InvalidArgumentError("depth image buffers do not match its size");
  }
  if (!depth_error.empty() && depth_error.size() != image.depth.size()) {
    return InvalidArgumentError("depth errors do not match the depth image's size");
  }
  // Not Clear(): the point buffers are resized below, keeping what they hold.
  out->far_local.clear();
  out->time = image.time;
  out->T_local_cam = T_local_body * camera_.T_body_cam;
  const Eigen::Matrix3f R = out->T_local_cam.linear().cast<float>();
  const Eigen::Vector3f t = out->T_local_cam.translation().cast<float>();
  const float fx_inv = static_cast<float>(1.0 / k.fx), fy_inv = static_cast<float>(1.0 / k.fy);
  const float cx = static_cast<float>(k.cx), cy = static_cast<float>(k.cy);
  const float zmin = static_cast<float>(options_.min_depth), zmax = static_cast<float>(range_);
  // Eq. 5.2c: dz = c z^2.
  const float c = static_cast<float>(model_.DepthError(1.0));
  const int stride = static_cast<int>(options_.far_ray_stride_px);
  const bool has_intensity = !image.intensity.empty();
  // Sized for every pixel and written through raw pointers, then cut to the points kept: with
  // push_back the uint8_t stores may alias the vectors' own pointers, which the compiler then
  // reloads and stores for every point. Resizing keeps the previous image's elements, so only the
  // few pixels beyond its point count are initialised.
  const size_t pixels = image.depth.size();
  out->p_cam.resize(pixels);
  out->p_local.resize(pixels);
  out->depth_error.resize(pixels);
  out->pixel.resize(pixels);
  out->intensity.resize(pixels);
  Eigen::Vector3f* p_cam = out->p_cam.data();
  Eigen::Vector3f* p_local = out->p_local.data();
  float* point_error = out->depth_error.data();
  const float* pixel_error = depth_error.empty() ? nullptr : depth_error.data();
  uint32_t* pixel = out->pixel.data();
  uint8_t* intensity = out->intensity.data();
  const uint8_t* gray = image.intensity.data();
  size_t n = 0;
  for (int v = 0; v < image.height; ++v) {
    const float y = (static_cast<float>(v) - cy) * fy_inv;
    const float* row = image.depth.data() + static_cast<size_t>(v) * static_cast<size_t>(image.width);
    const bool far_row = options_.clear_free_beyond_range && v % stride == 0;
    for (int u = 0; u < image.width; ++u) {
      const float z = row[u];
      if (!(z >= zmin)) continue;  // NaN or too close
      const float x = (static_cast<float>(u) - cx) * fx_inv;
      if (z <= zmax) {
        const Eigen::Vector3f p(x * z, y * z, z);
        const uint32_t pix = static_cast<uint32_t>(v * image.width + u);
        p_cam[n] = p;
        p_local[n] = R * p + t;
        point_error[n] = pixel_error != nullptr ? pixel_error[pix] : c * z * z;
        pixel[n] = pix;
        intensity[n] = has_intensity ? gray[pix] : uint8_t{0};
        ++n;
      } else if (far_row && u % stride == 0) {
        // The ray is free up to the range limit, measured along it like OctoMap's maxrange.
        const Eigen::Vector3f dir = Eigen::Vector3f(x, y, 1.0f).normalized();
        out->far_local.push_back(R * (dir * zmax) + t);
      }
    }
  }
  out->Truncate(n);
  out->obstacle.assign(n, 0);
  return Status::Ok();
}

}  // namespace cairn
