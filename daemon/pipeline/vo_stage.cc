#include "daemon/pipeline/vo_stage.h"

#include "common/monotonic_clock.h"

namespace cairn {

VoStage::VoStage(const VoOptions& vo, const FrameSwitchOptions& switches, const RectifiedStereoCamera& camera,
                 const Eigen::Isometry3d& T_body_cam)
    : vo_(vo, camera, T_body_cam), policy_(switches) {
  trajectory_.frame = "local/0";
  odometry_.frame = "odometry";
  // Hours of frames at 20 Hz before the vectors grow.
  trajectory_.poses.reserve(1 << 17);
  odometry_.poses.reserve(1 << 17);
}

VoResult VoStage::Process(const RectifiedPair& pair) {
  if (pair.dropped_before > 0) {
    report_.by_status[static_cast<size_t>(VoStatus::kDroppedFrame)] += static_cast<uint64_t>(pair.dropped_before);
    report_.frames += static_cast<uint64_t>(pair.dropped_before);
    vo_.ReportDropped(pair.dropped_before);
  }
  const MonotonicClock clock;
  const Timestamp start = clock.Now();
  const cv::Mat left(pair.left.height, pair.left.width, CV_8UC1, const_cast<uint8_t*>(pair.left.data.get()),
                     static_cast<size_t>(pair.left.stride));
  const cv::Mat right(pair.right.height, pair.right.width, CV_8UC1, const_cast<uint8_t*>(pair.right.data.get()),
                      static_cast<size_t>(pair.right.stride));
  VoResult r = vo_.Process(pair.time, left, right);
  vo_time_.Record(clock.Now() - start);
  ++report_.frames;
  ++report_.by_status[static_cast<size_t>(r.status)];
  report_.keyframes += r.new_keyframe ? 1 : 0;
  if (r.status == VoStatus::kOk || r.new_keyframe) odometry_.poses.push_back(StampedPose{r.time, r.T_odom_body});
  return r;
}

std::optional<FilterSwitchRequest> VoStage::OnEstimate(const FrameEstimate& e) {
  ++report_.estimates;
  if (e.keyframe_clone_missing) {
    vo_.DropKeyframe(e.keyframe_time);
    ++report_.keyframes_dropped_for_missing_clone;
  }
  if (!e.valid) return std::nullopt;
  ++report_.valid_estimates;
  trajectory_.poses.push_back(StampedPose{e.time, e.T_first_body});
  const FrameSwitchReason reason = policy_.Update(e.frame_id, e.T_frame_body.translation(), e.position_sigma);
  if (reason == FrameSwitchReason::kNone) return std::nullopt;
  return FilterSwitchRequest{e.time, reason};
}

}  // namespace cairn
