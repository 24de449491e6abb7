#include "estimation/vo/vo_types.h"

namespace cairn {

const char* VoStatusName(VoStatus s) {
  switch (s) {
    case VoStatus::kOk: return "ok";
    case VoStatus::kBadExposure: return "bad_exposure";
    case VoStatus::kSizeMismatch: return "size_mismatch";
    case VoStatus::kTooFewFeatures: return "too_few_features";
    case VoStatus::kTooFewTracks: return "too_few_tracks";
    case VoStatus::kTooFewInliers: return "too_few_inliers";
    case VoStatus::kDegenerate: return "degenerate";
    case VoStatus::kDroppedFrame: return "dropped_frame";
    case VoStatus::kNoKeyframe: return "no_keyframe";
  }
  return "unknown";
}

bool TriangulateStereo(const RectifiedStereoCamera& cam, const StereoObservation& o, double pixel_sigma,
                       double min_disparity, StereoPoint* out) {
  const double d = o.u_left - o.u_right;
  if (!(d >= min_disparity) || cam.f <= 0.0 || cam.baseline <= 0.0) return false;
  const double b = cam.baseline;
  const double x = b * (o.u_left - cam.cx) / d;
  const double y = b * (o.v - cam.cy) / d;
  const double z = cam.f * b / d;
  out->p = Eigen::Vector3d(x, y, z);
  // Jacobian with respect to (u_left, u_right, v).
  Eigen::Matrix3d J;
  J << (b - x) / d, x / d, 0.0,
       -y / d, y / d, b / d,
       -z / d, z / d, 0.0;
  const Eigen::Vector3d var(pixel_sigma * pixel_sigma, pixel_sigma * pixel_sigma, 0.5 * pixel_sigma * pixel_sigma);
  out->cov = J * var.asDiagonal() * J.transpose();
  return true;
}

}  // namespace cairn
