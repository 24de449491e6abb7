#include "daemon/pipeline/stereo_rectify_stage.h"

#include <cmath>

namespace cairn {
namespace {

// Both cameras share intrinsics, have no distortion and differ by a pure x translation.
bool AlreadyRectified(const StereoCalibration& c) {
  const PinholeRadTan& a = c.left.intrinsics;
  const PinholeRadTan& b = c.right.intrinsics;
  const auto zero = [](const PinholeRadTan& k) { return k.k1 == 0.0 && k.k2 == 0.0 && k.p1 == 0.0 && k.p2 == 0.0; };
  const Eigen::Isometry3d T = c.T_left_right();
  return zero(a) && zero(b) && a.fx == b.fx && a.fy == b.fy && a.fx == a.fy && a.cx == b.cx && a.cy == b.cy &&
         (T.linear() - Eigen::Matrix3d::Identity()).norm() < 1e-9 && std::abs(T.translation().y()) < 1e-9 &&
         std::abs(T.translation().z()) < 1e-9 && T.translation().x() > 0.0;
}

}  // namespace

Expected<std::unique_ptr<StereoRectifyStage>> StereoRectifyStage::Create(const StereoCalibration& calibration,
                                                                         size_t pool) {
  auto stage = std::make_unique<StereoRectifyStage>();
  const PinholeRadTan& k = calibration.left.intrinsics;
  stage->camera_.width = k.width;
  stage->camera_.height = k.height;
  if (AlreadyRectified(calibration)) {
    stage->camera_.f = k.fx;
    stage->camera_.cx = k.cx;
    stage->camera_.cy = k.cy;
    stage->camera_.baseline = calibration.baseline();
    stage->T_body_cam_ = calibration.left.T_body_cam;
    return stage;
  }
  Expected<StereoRectifier> r = StereoRectifier::Create(calibration);
  if (!r.ok()) return r.status();
  stage->rectifier_ = std::move(*r);
  stage->camera_.f = stage->rectifier_->focal_px();
  stage->camera_.cx = stage->rectifier_->cx();
  stage->camera_.cy = stage->rectifier_->cy();
  stage->camera_.baseline = stage->rectifier_->baseline();
  Eigen::Isometry3d T_cam_rect = Eigen::Isometry3d::Identity();
  T_cam_rect.linear() = stage->rectifier_->R_left_rect();
  stage->T_body_cam_ = calibration.left.T_body_cam * T_cam_rect;
  const size_t bytes = static_cast<size_t>(k.width) * static_cast<size_t>(k.height);
  for (size_t i = 0; i < pool; ++i) {
    stage->left_pool_.emplace_back(new uint8_t[bytes]);
    stage->right_pool_.emplace_back(new uint8_t[bytes]);
  }
  return stage;
}

std::shared_ptr<uint8_t[]> StereoRectifyStage::FreeBuffer(std::vector<std::shared_ptr<uint8_t[]>>& pool) const {
  // A buffer only the pool references is free (its consumers have let go).
  for (const auto& b : pool) {
    if (b.use_count() == 1) return b;
  }
  return nullptr;
}

bool StereoRectifyStage::Rectify(const StereoFrame& frame, RectifiedPair* out) {
  out->time = frame.time;
  out->frame_counter = frame.frame_counter;
  for (const Image* im : {&frame.left, &frame.right}) {
    if (im->empty() || im->format != PixelFormat::kGray8 || im->width != camera_.width || im->height != camera_.height) {
      return false;
    }
  }
  if (!rectifier_) {
    out->left = frame.left;
    out->right = frame.right;
    return true;
  }
  std::shared_ptr<uint8_t[]> l = FreeBuffer(left_pool_), r = FreeBuffer(right_pool_);
  if (!l || !r) return false;
  const auto view = [](const Image& im) {
    return cv::Mat(im.height, im.width, CV_8UC1, const_cast<uint8_t*>(im.data.get()), static_cast<size_t>(im.stride));
  };
  cv::Mat lo(camera_.height, camera_.width, CV_8UC1, l.get()), ro(camera_.height, camera_.width, CV_8UC1, r.get());
  if (!rectifier_->Rectify(view(frame.left), view(frame.right), &lo, &ro).ok()) return false;
  const auto image = [&](std::shared_ptr<uint8_t[]> b) {
    Image im;
    im.data = std::move(b);
    im.width = camera_.width;
    im.height = camera_.height;
    im.stride = camera_.width;
    im.format = PixelFormat::kGray8;
    return im;
  };
  out->left = image(l);
  out->right = image(r);
  return true;
}

}  // namespace cairn
