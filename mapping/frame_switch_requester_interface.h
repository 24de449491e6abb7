#pragma once
// How mapping asks the local reference filter for a frame switch (thesis 5.1.3, 4.1.2). The daemon
// implements this on top of LocalReferenceFilter::RequestFrameSwitch (through the estimation
// executor's request path); the filter's FrameSwitchResult then starts the new submap and goes to
// the SLAM graph.

#include <cstdint>

#include "common/timestamp.h"

namespace cairn {

enum class PartitionReason : uint8_t { kPositionSigma, kDistance };

struct FrameSwitchRequest {
  Timestamp time;            // of the pose that triggered it
  uint64_t frame_id = 0;     // the local frame (= open submap) to leave
  PartitionReason reason = PartitionReason::kDistance;
  double position_sigma = 0.0;  // m, largest standard deviation at the request
  double distance = 0.0;        // m travelled in this frame
};

class FrameSwitchRequesterInterface {
 public:
  virtual ~FrameSwitchRequesterInterface() = default;
  // Must not block: called from the mapping thread.
  virtual void RequestFrameSwitch(const FrameSwitchRequest& request) = 0;
};

}  // namespace cairn
