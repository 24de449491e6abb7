#pragma once
// When to switch the filter's frame of reference until submap partitioning exists: after
// `max_distance` travelled in the current frame or when the position sigma passes
// `max_position_sigma` (the thesis' new-submap criteria, 5.1.3). Fed with the filter's estimates;
// one request per frame (it waits for the frame id to change before asking again).

#include <cstdint>

#include <Eigen/Core>

#include "estimation/vo/vo_options.h"

namespace cairn {

enum class FrameSwitchReason : uint8_t { kNone, kDistance, kPositionSigma };
const char* FrameSwitchReasonName(FrameSwitchReason r);

class FrameSwitchPolicy {
 public:
  explicit FrameSwitchPolicy(const FrameSwitchOptions& options) : options_(options) {}

  // One estimate: position of the body in local frame `frame_id` and the largest standard
  // deviation of that position. Returns why a switch is due now (kNone if not).
  FrameSwitchReason Update(uint64_t frame_id, const Eigen::Vector3d& p_frame_body, double position_sigma);

  double distance() const { return distance_; }

 private:
  FrameSwitchOptions options_;
  bool have_ = false;
  uint64_t frame_id_ = 0;
  Eigen::Vector3d last_ = Eigen::Vector3d::Zero();
  double distance_ = 0.0;
  bool requested_ = false;
};

}  // namespace cairn
