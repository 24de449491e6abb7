#include "mapping/depth_fusion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace cairn {
namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
}  // namespace

DepthFusion::DepthFusion(const DepthFusionOptions& options, const StereoCamera& camera, const StereoErrorModel& model)
    : options_(options), intrinsics_(camera.intrinsics), c_(static_cast<float>(model.DepthError(1.0))) {
  const size_t n = static_cast<size_t>(intrinsics_.width) * static_cast<size_t>(intrinsics_.height);
  previous_depth_.resize(n);
  previous_sigma_.resize(n);
  out_.width = intrinsics_.width;
  out_.height = intrinsics_.height;
  out_.depth.resize(n);
  out_.intensity.reserve(n);
  out_sigma_.resize(n);
  ray_x_.resize(static_cast<size_t>(intrinsics_.width));
  for (int u = 0; u < intrinsics_.width; ++u) {
    ray_x_[static_cast<size_t>(u)] = static_cast<float>((u - intrinsics_.cx) / intrinsics_.fx);
  }
}

void DepthFusion::Rebase(const Eigen::Isometry3d& T_old_new) {
  T_local_previous_ = T_old_new.inverse() * T_local_previous_;
}

bool DepthFusion::Sample(float u, float v, float* depth, float* sigma) const {
  const int w = intrinsics_.width, h = intrinsics_.height;
  if (!(u >= 0.0f && v >= 0.0f && u <= static_cast<float>(w - 1) && v <= static_cast<float>(h - 1))) return false;
  const int u0 = std::min(static_cast<int>(u), w - 2), v0 = std::min(static_cast<int>(v), h - 2);
  const float au = u - static_cast<float>(u0), av = v - static_cast<float>(v0);
  const size_t i = static_cast<size_t>(v0) * static_cast<size_t>(w) + static_cast<size_t>(u0);
  const size_t idx[4] = {i, i + 1, i + static_cast<size_t>(w), i + static_cast<size_t>(w) + 1};
  const float wk[4] = {(1 - au) * (1 - av), au * (1 - av), (1 - au) * av, au * av};
  float d[4], s[4];
  bool all = true;
  for (int k = 0; k < 4; ++k) {
    d[k] = previous_depth_[idx[k]];
    s[k] = previous_sigma_[idx[k]];
    all = all && d[k] < kInf;  // false for NaN too
  }
  if (all) {
    // Interpolated only within one surface: across a depth edge the mean lies on neither side.
    const float lo = std::min(std::min(d[0], d[1]), std::min(d[2], d[3]));
    const float hi = std::max(std::max(d[0], d[1]), std::max(d[2], d[3]));
    const float smax = std::max(std::max(s[0], s[1]), std::max(s[2], s[3]));
    if (hi - lo <= static_cast<float>(options_.agreement_sigmas) * smax) {
      *depth = wk[0] * d[0] + wk[1] * d[1] + wk[2] * d[2] + wk[3] * d[3];
      *sigma = wk[0] * s[0] + wk[1] * s[1] + wk[2] * s[2] + wk[3] * s[3];
      return true;
    }
  }
  // Otherwise the nearest of the four with a depth: an invalid stereo pixel next to the warped
  // position should not end a pixel's history.
  int best = -1;
  for (int k = 0; k < 4; ++k) {
    if (d[k] < kInf && (best < 0 || wk[k] > wk[best])) best = k;
  }
  if (best < 0) return false;
  *depth = d[best];
  *sigma = s[best];
  return true;
}

Status DepthFusion::Fuse(const DepthImage& image, const Eigen::Isometry3d& T_local_cam) {
  const int w = intrinsics_.width, h = intrinsics_.height;
  if (image.width != w || image.height != h || image.depth.size() != out_.depth.size()) {
    return InvalidArgumentError("depth fusion: image " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + " does not match camera " + std::to_string(w) + "x" +
                                std::to_string(h));
  }
  if (!T_local_cam.matrix().allFinite()) return InvalidArgumentError("depth fusion: camera pose is not finite");
  std::swap(previous_depth_, out_.depth);
  std::swap(previous_sigma_, out_sigma_);
  out_.time = image.time;
  out_.intensity.assign(image.intensity.begin(), image.intensity.end());

  // Point of the new camera -> previous camera.
  const Eigen::Isometry3d T_previous_new = T_local_previous_.inverse() * T_local_cam;
  const Eigen::Matrix3f R = T_previous_new.linear().cast<float>();
  const Eigen::Vector3f t = T_previous_new.translation().cast<float>();
  // The new camera's z axis in the previous camera: depth of a previous-camera point q in the new
  // camera is r . (q - t).
  const Eigen::Vector3f r = R.col(2);
  const float rt = r.dot(t);
  const float fx = static_cast<float>(intrinsics_.fx), fy = static_cast<float>(intrinsics_.fy);
  const float cx = static_cast<float>(intrinsics_.cx), cy = static_cast<float>(intrinsics_.cy);
  const float k2 = static_cast<float>(options_.agreement_sigmas * options_.agreement_sigmas);
  // The prior weighs at most (max_images - 1) new measurements: its variance is taken as at least
  // the new one's / (max_images - 1), so the fused variance stays >= sigma^2 / max_images.
  const float min_prior_share = options_.max_images > 1 ? 1.0f / static_cast<float>(options_.max_images - 1) : 0.0f;
  const bool warp = has_previous_ && options_.max_images > 1;
  const float* in = image.depth.data();
  float* depth = out_.depth.data();
  float* sigma_out = out_sigma_.data();
  const float* ray_x = ray_x_.data();
  int64_t measured = 0, fused = 0;
  for (int v = 0; v < h; ++v) {
    const size_t row = static_cast<size_t>(v) * static_cast<size_t>(w);
    const float y = (static_cast<float>(v) - cy) / fy;
    // R (x, y, 1) along the row: the ray of pixel (u, v) in the previous camera.
    const Eigen::Vector3f base = R.col(1) * y + R.col(2);
    for (int u = 0; u < w; ++u) {
      const size_t i = row + static_cast<size_t>(u);
      const float z = in[i];
      depth[i] = z;
      if (!(z > 0.0f && z < kInf)) {
        sigma_out[i] = kInf;
        continue;
      }
      ++measured;
      const float sigma = c_ * z * z;
      sigma_out[i] = sigma;
      if (!warp) continue;
      const Eigen::Vector3f p = (base + R.col(0) * ray_x[u]) * z + t;  // in the previous camera
      if (!(p.z() > 0.0f)) continue;
      const float inv_pz = 1.0f / p.z();
      float zf = 0.0f, sf = 0.0f;
      if (!Sample(fx * p.x() * inv_pz + cx, fy * p.y() * inv_pz + cy, &zf, &sf)) continue;
      // The fused surface on the previous camera's ray through p, seen from the new camera: the
      // point (zf / p.z) p, whose new depth is r . ((zf / p.z) p - t) with r . p = z + r . t.
      const float predicted = zf * inv_pz * (z + rt) - rt;
      const float var_new = sigma * sigma, var_prior = std::max(sf * sf, var_new * min_prior_share);
      const float diff = z - predicted, var_sum = var_new + var_prior;
      if (diff * diff > k2 * var_sum) continue;
      // Inverse-variance weights, in variances: one division.
      const float inv_sum = 1.0f / var_sum;
      depth[i] = (var_prior * z + var_new * predicted) * inv_sum;
      sigma_out[i] = std::sqrt(var_new * var_prior * inv_sum);
      ++fused;
    }
  }
  stats_.measured = measured;
  stats_.fused = fused;
  T_local_previous_ = T_local_cam;
  has_previous_ = true;
  return Status::Ok();
}

}  // namespace cairn
