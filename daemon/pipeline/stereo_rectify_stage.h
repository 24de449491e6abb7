#pragma once
// Stereo-thread step before the odometry: rectifies each pair with maps computed once from the
// calibration, into a small pool of reused buffers. A calibration that is already rectified
// (simulated cameras) passes the images through without a copy.

#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "estimation/vo/vo_types.h"
#include "hal/calibration.h"
#include "hal/stereo_frame.h"
#include "stereo/stereo_rectifier.h"

namespace cairn {

struct RectifiedPair {
  Timestamp time;
  uint64_t frame_counter = 0;
  int dropped_before = 0;  // frames the camera numbered but never delivered, just before this one
  Image left, right;
};

class StereoRectifyStage {
 public:
  // `pool` buffers per image: enough for the frames in flight to the odometry.
  static Expected<std::unique_ptr<StereoRectifyStage>> Create(const StereoCalibration& calibration, size_t pool);

  // False when the frame has the wrong size or format, or every buffer is still in use.
  bool Rectify(const StereoFrame& frame, RectifiedPair* out);

  const RectifiedStereoCamera& camera() const { return camera_; }
  // Pose of the rectified left camera in the body frame.
  const Eigen::Isometry3d& T_body_cam() const { return T_body_cam_; }
  bool pass_through() const { return !rectifier_.has_value(); }

 private:
  std::shared_ptr<uint8_t[]> FreeBuffer(std::vector<std::shared_ptr<uint8_t[]>>& pool) const;

  RectifiedStereoCamera camera_;
  Eigen::Isometry3d T_body_cam_ = Eigen::Isometry3d::Identity();
  std::optional<StereoRectifier> rectifier_;
  std::vector<std::shared_ptr<uint8_t[]>> left_pool_, right_pool_;
};

}  // namespace cairn
