#include "estimation/vo/frame_switch_policy.h"

namespace cairn {

const char* FrameSwitchReasonName(FrameSwitchReason r) {
  switch (r) {
    case FrameSwitchReason::kNone: return "none";
    case FrameSwitchReason::kDistance: return "distance";
    case FrameSwitchReason::kPositionSigma: return "position_sigma";
  }
  return "unknown";
}

FrameSwitchReason FrameSwitchPolicy::Update(uint64_t frame_id, const Eigen::Vector3d& p, double position_sigma) {
  if (!have_ || frame_id != frame_id_) {
    // A new frame starts at the body: distance counts from here.
    have_ = true;
    frame_id_ = frame_id;
    last_ = p;
    distance_ = 0.0;
    requested_ = false;
  } else {
    distance_ += (p - last_).norm();
    last_ = p;
  }
  if (!options_.enabled || requested_ || !p.allFinite()) return FrameSwitchReason::kNone;
  FrameSwitchReason r = FrameSwitchReason::kNone;
  if (distance_ >= options_.max_distance) {
    r = FrameSwitchReason::kDistance;
  } else if (position_sigma > options_.max_position_sigma) {
    r = FrameSwitchReason::kPositionSigma;
  }
  requested_ = r != FrameSwitchReason::kNone;
  return r;
}

}  // namespace cairn
