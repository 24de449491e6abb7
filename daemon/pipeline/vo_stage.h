#pragma once
// The odometry thread's work: keyframe stereo visual odometry on rectified pairs, the raw
// odometry chain (vo.tum), the filter's per-frame estimates coming back (trajectory.tum,
// keyframes whose clone is gone) and the frame-switch policy that stands in for submap
// partitioning: its requests take the path mapping will use (Pipeline::RequestFilterSwitch).

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "daemon/pipeline/estimation_stage.h"
#include "daemon/pipeline/latency_histogram.h"
#include "daemon/pipeline/stereo_rectify_stage.h"
#include "estimation/eval/trajectory.h"
#include "estimation/vo/frame_switch_policy.h"
#include "estimation/vo/keyframe_visual_odometry.h"

namespace cairn {

struct VoStageReport {
  uint64_t frames = 0;  // pairs processed (plus dropped ones counted by status)
  std::array<uint64_t, kVoStatusCount> by_status{};
  uint64_t keyframes = 0;
  uint64_t estimates = 0;        // filter estimates received
  uint64_t valid_estimates = 0;  // of which the filter covered the frame
  uint64_t keyframes_dropped_for_missing_clone = 0;
};

class VoStage {
 public:
  VoStage(const VoOptions& vo, const FrameSwitchOptions& switches, const RectifiedStereoCamera& camera,
          const Eigen::Isometry3d& T_body_cam);

  VoResult Process(const RectifiedPair& pair);
  // The filter's estimate at a frame; returns a frame-switch request when one is due.
  std::optional<FilterSwitchRequest> OnEstimate(const FrameEstimate& e);

  const VoStageReport& report() const { return report_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const Trajectory& odometry() const { return odometry_; }
  const LatencyHistogram& vo_time() const { return vo_time_; }

 private:
  KeyframeVisualOdometry vo_;
  FrameSwitchPolicy policy_;
  VoStageReport report_;
  Trajectory trajectory_, odometry_;
  LatencyHistogram vo_time_;
};

}  // namespace cairn
