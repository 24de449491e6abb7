#pragma once
// Keyframe-based stereo visual odometry (thesis 4.1.1 after Hirschmueller et al. 2002): every
// rectified pair is matched against one of a few keyframes (default 5) and yields the delta pose
// of the body between that keyframe and the current frame, with covariance, for the local
// reference filter (which holds a clone per keyframe). Matching against an old keyframe while it
// still overlaps keeps the estimate locally drift-free, e.g. while hovering or standing.
//
// Per frame: exposure check, pyramids, choice of the keyframe nearest to the predicted pose
// (the oldest among equals), Lucas-Kanade tracking of its corners, sparse stereo in the current
// pair, RANSAC, alignment and bundle adjustment (estimation/vo/stereo_pose_estimator.h). A frame
// becomes a keyframe when the tracked share or the motion since its keyframe passes the
// thresholds; the farthest keyframe then makes room. Failures carry a reason and no estimate.

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "common/timestamp.h"
#include "estimation/vo/stereo_feature_tracker.h"
#include "estimation/vo/stereo_pose_estimator.h"
#include "estimation/vo/vo_options.h"
#include "estimation/vo/vo_types.h"

namespace cairn {

struct VoResult {
  Timestamp time;
  VoStatus status = VoStatus::kNoKeyframe;
  // Valid when status == kOk: body pose of the current frame in the keyframe's body frame and
  // the covariance of [translation; rotation (right perturbation)] in the keyframe body frame
  // (the filter's relative-pose convention).
  Timestamp keyframe_time;
  Eigen::Isometry3d T_kf_cur = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Identity();
  // The current frame became a keyframe: later results may reference it.
  bool new_keyframe = false;
  // Keyframes dropped by this frame (no later result references them).
  int removed_count = 0;
  std::array<Timestamp, kMaxVoKeyframes> removed{};
  // Raw odometry chain: body pose in the frame of the first keyframe.
  Eigen::Isometry3d T_odom_body = Eigen::Isometry3d::Identity();
  int features = 0;  // keyframe features tried
  int tracks = 0;    // found again with a stereo match
  int inliers = 0;
};

class KeyframeVisualOdometry {
 public:
  // `T_body_cam`: pose of the rectified left camera in the body frame.
  KeyframeVisualOdometry(const VoOptions& options, const RectifiedStereoCamera& camera,
                         const Eigen::Isometry3d& T_body_cam);

  // One rectified 8-bit pair of the calibrated size (the pixels are read during the call only:
  // a keyframe keeps its own pyramid copies).
  VoResult Process(Timestamp time, const cv::Mat& left, const cv::Mat& right);
  // The camera lost `count` frames before the next one: reported as failures, no state change.
  void ReportDropped(int count) { consecutive_failures_ += count; }
  // The keyframe taken at `time` has no filter clone (gone, or taken before the filter ran): it
  // is no longer a reference for delta poses. It still serves to track the next frame, which
  // then becomes a keyframe, so the odometry chain continues.
  void DropKeyframe(Timestamp time);

  int keyframe_count() const { return static_cast<int>(keyframes_.size()); }
  const RectifiedStereoCamera& camera() const { return camera_; }

 private:
  struct Keyframe {
    Timestamp time;
    StereoPyramids pair;  // pyramids only; the level-0 views are cleared
    std::vector<cv::Point2f> left_px;
    std::vector<StereoPoint> points;  // in the keyframe camera
    std::vector<StereoObservation> seen;  // the pixels each point was triangulated from
    Eigen::Isometry3d T_odom_cam = Eigen::Isometry3d::Identity();
    bool referable = true;  // false once its filter clone is known to be missing
  };

  bool ExposureOk(const cv::Mat& image) const;
  // Makes the current pair a keyframe; false when it has too few triangulated features.
  bool AddKeyframe(Timestamp time, const Eigen::Isometry3d& T_odom_cam, VoResult* result);
  PoseEstimate MatchKeyframe(const Keyframe& kf, const Eigen::Isometry3d& T_kf_cur_pred, uint64_t seed,
                             VoResult* result);
  double Distance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) const;
  void Fail(VoStatus status, VoResult* result);
  void Finish(VoResult* result) const;

  VoOptions options_;
  RectifiedStereoCamera camera_;
  Eigen::Isometry3d T_body_cam_;
  StereoFeatureTracker tracker_;
  StereoPoseEstimator estimator_;
  std::vector<Keyframe> keyframes_;  // oldest first
  StereoPyramids current_;
  Eigen::Isometry3d T_odom_cam_ = Eigen::Isometry3d::Identity();  // last estimate
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();    // T_prev_cur of the last step
  int64_t consecutive_failures_ = 0;
  uint64_t frames_ = 0;
  // Scratch.
  std::vector<StereoObservation> observations_;
  std::vector<uint8_t> found_;
  std::vector<cv::Point2f> predicted_;
  std::vector<float> predicted_disparity_;
  std::vector<StereoPoint> kf_points_, cur_points_;
  std::vector<StereoObservation> kf_seen_, cur_seen_;
  std::vector<int> index_;
};

}  // namespace cairn
