#include "estimation/vo/keyframe_visual_odometry.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "estimation/math/so3.h"

namespace cairn {
namespace {

double AngleOf(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

}  // namespace

KeyframeVisualOdometry::KeyframeVisualOdometry(const VoOptions& options, const RectifiedStereoCamera& camera,
                                               const Eigen::Isometry3d& T_body_cam)
    : options_(options),
      camera_(camera),
      T_body_cam_(T_body_cam),
      tracker_(options, camera),
      estimator_(options, camera) {
  keyframes_.reserve(static_cast<size_t>(options.keyframes) + 1);
}

void KeyframeVisualOdometry::DropKeyframe(Timestamp time) {
  for (Keyframe& k : keyframes_) {
    if (k.time == time) k.referable = false;
  }
}

bool KeyframeVisualOdometry::ExposureOk(const cv::Mat& image) const {
  // Every 4th pixel of every 4th row is plenty to tell a usable image from a blank one.
  double sum = 0.0, sum2 = 0.0;
  int64_t n = 0;
  for (int y = 0; y < image.rows; y += 4) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    for (int x = 0; x < image.cols; x += 4) {
      const double v = row[x];
      sum += v;
      sum2 += v * v;
      ++n;
    }
  }
  if (n == 0) return false;
  const double mean = sum / static_cast<double>(n);
  const double var = std::max(0.0, sum2 / static_cast<double>(n) - mean * mean);
  return mean >= options_.min_mean && mean <= options_.max_mean && std::sqrt(var) >= options_.min_contrast;
}

double KeyframeVisualOdometry::Distance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) const {
  const Eigen::Isometry3d rel = a.inverse() * b;
  return rel.translation().norm() / std::max(options_.keyframe_translation, 1e-3) +
         AngleOf(rel.linear()) / std::max(options_.keyframe_rotation_deg * M_PI / 180.0, 1e-3);
}

void KeyframeVisualOdometry::Fail(VoStatus status, VoResult* result) {
  result->status = status;
  ++consecutive_failures_;
}

void KeyframeVisualOdometry::Finish(VoResult* result) const {
  result->T_odom_body = T_body_cam_ * T_odom_cam_ * T_body_cam_.inverse();
}

bool KeyframeVisualOdometry::AddKeyframe(Timestamp time, const Eigen::Isometry3d& T_odom_cam, VoResult* result) {
  tracker_.DetectAndMatch(current_, &observations_);
  Keyframe kf;
  kf.time = time;
  kf.T_odom_cam = T_odom_cam;
  kf.left_px.reserve(observations_.size());
  kf.points.reserve(observations_.size());
  kf.seen.reserve(observations_.size());
  for (const StereoObservation& o : observations_) {
    StereoPoint p;
    if (!TriangulateStereo(camera_, o, options_.pixel_sigma, options_.min_disparity, &p)) continue;
    if (p.cov(2, 2) > options_.max_depth_error * options_.max_depth_error) continue;
    kf.left_px.emplace_back(static_cast<float>(o.u_left), static_cast<float>(o.v));
    kf.points.push_back(p);
    kf.seen.push_back(o);
  }
  if (static_cast<int64_t>(kf.points.size()) < options_.min_tracks) return false;
  if (static_cast<int64_t>(keyframes_.size()) >= options_.keyframes) {
    // Drop the keyframe farthest from the new one (the oldest among equals): the set stays local.
    size_t victim = 0;
    double worst = -1.0;
    for (size_t i = 0; i < keyframes_.size(); ++i) {
      // Keyframes without a filter clone go first.
      const double d = Distance(keyframes_[i].T_odom_cam, T_odom_cam) + (keyframes_[i].referable ? 0.0 : 1e6);
      if (d > worst) {
        worst = d;
        victim = i;
      }
    }
    result->removed[static_cast<size_t>(result->removed_count++)] = keyframes_[victim].time;
    // Its pyramid buffers are reused for the next frames.
    std::swap(kf.pair.left_pyramid, keyframes_[victim].pair.left_pyramid);
    std::swap(kf.pair.right_pyramid, keyframes_[victim].pair.right_pyramid);
    keyframes_.erase(keyframes_.begin() + static_cast<std::ptrdiff_t>(victim));
  }
  std::swap(kf.pair.left_pyramid, current_.left_pyramid);
  std::swap(kf.pair.right_pyramid, current_.right_pyramid);
  keyframes_.push_back(std::move(kf));
  result->new_keyframe = true;
  return true;
}

PoseEstimate KeyframeVisualOdometry::MatchKeyframe(const Keyframe& kf, const Eigen::Isometry3d& T_kf_cur_pred,
                                                   uint64_t seed, VoResult* result) {
  const Eigen::Isometry3d T_cur_kf = T_kf_cur_pred.inverse();
  const size_t n = kf.points.size();
  predicted_.resize(n);
  predicted_disparity_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p = T_cur_kf * kf.points[i].p;
    if (p.z() < 0.05) {
      predicted_[i] = kf.left_px[i];
      predicted_disparity_[i] = static_cast<float>(camera_.f * camera_.baseline / kf.points[i].p.z());
      continue;
    }
    predicted_[i] = cv::Point2f(static_cast<float>(camera_.f * p.x() / p.z() + camera_.cx),
                                static_cast<float>(camera_.f * p.y() / p.z() + camera_.cy));
    predicted_disparity_[i] = static_cast<float>(camera_.f * camera_.baseline / p.z());
  }
  tracker_.Track(kf.pair, kf.left_px, predicted_, predicted_disparity_, current_, &observations_, &found_);
  kf_points_.clear();
  cur_points_.clear();
  kf_seen_.clear();
  cur_seen_.clear();
  index_.clear();
  for (size_t i = 0; i < n; ++i) {
    if (!found_[i]) continue;
    StereoPoint p;
    if (!TriangulateStereo(camera_, observations_[i], options_.pixel_sigma, options_.min_disparity, &p)) continue;
    if (p.cov(2, 2) > options_.max_depth_error * options_.max_depth_error) continue;
    kf_points_.push_back(kf.points[i]);
    cur_points_.push_back(p);
    kf_seen_.push_back(kf.seen[i]);
    cur_seen_.push_back(observations_[i]);
    index_.push_back(static_cast<int>(i));
  }
  result->features = static_cast<int>(n);
  result->tracks = static_cast<int>(cur_points_.size());
  PoseEstimate e;
  if (static_cast<int64_t>(cur_points_.size()) < options_.min_tracks) {
    e.status = VoStatus::kTooFewTracks;
    return e;
  }
  e = estimator_.Estimate(kf_seen_, cur_seen_, kf_points_, cur_points_, seed);
  result->inliers = e.inliers;
  if (e.status != VoStatus::kOk) return e;
  // Inliers bunched on one spot constrain the rotation poorly even when the covariance
  // (first order) looks fine.
  float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
  const std::vector<uint8_t>& mask = estimator_.inlier_mask();
  for (size_t k = 0; k < index_.size(); ++k) {
    if (!mask[k]) continue;
    const StereoObservation& o = observations_[static_cast<size_t>(index_[k])];
    x0 = std::min(x0, static_cast<float>(o.u_left));
    x1 = std::max(x1, static_cast<float>(o.u_left));
    y0 = std::min(y0, static_cast<float>(o.v));
    y1 = std::max(y1, static_cast<float>(o.v));
  }
  const double spread = std::hypot(x1 - x0, y1 - y0) / std::hypot(camera_.width, camera_.height);
  if (spread < options_.min_inlier_spread) e.status = VoStatus::kDegenerate;
  return e;
}

VoResult KeyframeVisualOdometry::Process(Timestamp time, const cv::Mat& left, const cv::Mat& right) {
  VoResult r;
  r.time = time;
  ++frames_;
  if (left.cols != camera_.width || left.rows != camera_.height || right.size() != left.size() ||
      left.type() != CV_8UC1 || right.type() != CV_8UC1) {
    Fail(VoStatus::kSizeMismatch, &r);
    Finish(&r);
    return r;
  }
  if (!ExposureOk(left) || !ExposureOk(right)) {
    Fail(VoStatus::kBadExposure, &r);
    Finish(&r);
    return r;
  }
  tracker_.Prepare(left, right, &current_);

  if (keyframes_.empty() || consecutive_failures_ >= options_.max_consecutive_failures) {
    // (Re)start: the frame becomes the only keyframe. The raw chain continues from its last pose
    // (the motion during the outage is unknown to the odometry; the filter bridges it with the IMU).
    for (const Keyframe& k : keyframes_) r.removed[static_cast<size_t>(r.removed_count++)] = k.time;
    keyframes_.clear();
    velocity_.setIdentity();
    if (AddKeyframe(time, T_odom_cam_, &r)) {
      consecutive_failures_ = 0;
      r.status = VoStatus::kNoKeyframe;
    } else {
      Fail(VoStatus::kTooFewFeatures, &r);
    }
    Finish(&r);
    return r;
  }

  const Eigen::Isometry3d T_odom_pred = T_odom_cam_ * velocity_;
  size_t best = 0;
  double best_d = 1e300;
  for (size_t i = 0; i < keyframes_.size(); ++i) {
    // Referable keyframes first; among them strictly nearer only, so that among equally near
    // keyframes the oldest (least drift) wins.
    const double d = Distance(keyframes_[i].T_odom_cam, T_odom_pred) + (keyframes_[i].referable ? 0.0 : 1e6);
    if (d < best_d - 1e-9) {
      best_d = d;
      best = i;
    }
  }
  const Keyframe* kf = &keyframes_[best];
  PoseEstimate e = MatchKeyframe(*kf, kf->T_odom_cam.inverse() * T_odom_pred, frames_, &r);
  if (e.status != VoStatus::kOk && best + 1 != keyframes_.size()) {
    kf = &keyframes_.back();
    e = MatchKeyframe(*kf, kf->T_odom_cam.inverse() * T_odom_pred, frames_, &r);
  }
  if (e.status != VoStatus::kOk) {
    Fail(e.status, &r);
    Finish(&r);
    return r;
  }
  consecutive_failures_ = 0;
  const Eigen::Isometry3d T_odom_new = kf->T_odom_cam * e.T_kf_cur;
  velocity_ = T_odom_cam_.inverse() * T_odom_new;
  T_odom_cam_ = T_odom_new;

  // Camera delta to body delta: T_b = X T_c X^-1 with X = T_body_cam; for t += dt,
  // R <- R Exp(dtheta): dt_b = R_X dt + R_b [t_X]x R_X dtheta, dtheta_b = R_X dtheta.
  const Eigen::Isometry3d& X = T_body_cam_;
  r.T_kf_cur = X * e.T_kf_cur * X.inverse();
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = X.linear();
  J.topRightCorner<3, 3>() = r.T_kf_cur.linear() * so3::Skew(X.translation()) * X.linear();
  J.bottomRightCorner<3, 3>() = X.linear();
  r.covariance = J * e.covariance * J.transpose();
  r.covariance = 0.5 * (r.covariance + r.covariance.transpose()).eval();
  r.keyframe_time = kf->time;
  r.status = VoStatus::kOk;
  if (!kf->referable) {
    // Tracked for the chain only: no delta pose for the filter; this frame becomes a keyframe.
    r.status = VoStatus::kNoKeyframe;
    AddKeyframe(time, T_odom_cam_, &r);
    Finish(&r);
    return r;
  }

  const double tracked_ratio = static_cast<double>(e.inliers) / static_cast<double>(std::max<size_t>(1, kf->points.size()));
  if (tracked_ratio < options_.keyframe_min_tracked_ratio ||
      e.T_kf_cur.translation().norm() > options_.keyframe_translation ||
      AngleOf(e.T_kf_cur.linear()) > options_.keyframe_rotation_deg * M_PI / 180.0) {
    AddKeyframe(time, T_odom_cam_, &r);  // a frame without enough features stays a plain frame
  }
  Finish(&r);
  return r;
}

}  // namespace cairn
