#pragma once
// Submap partitioning policy (thesis 5.1.3): a new submap, i.e. a filter frame switch, once the
// position standard deviation exceeds a limit or the robot has travelled a distance in the current
// frame. The request repeats after `retry_interval` until the filter reports the new frame.

#include <Eigen/Core>

#include "mapping/frame_switch_requester_interface.h"
#include "mapping/mapping_options.h"

namespace cairn {

class SubmapPartitioner {
 public:
  // `requester` must outlive the partitioner.
  SubmapPartitioner(const PartitionOptions& options, FrameSwitchRequesterInterface* requester);

  // One filter estimate: body position in local frame `frame_id` and its 3x3 covariance. Returns
  // true when it sent a request. A new frame_id restarts the distance.
  bool Update(Timestamp time, uint64_t frame_id, const Eigen::Vector3d& p_local_body,
              const Eigen::Matrix3d& position_covariance);

  double distance() const { return distance_; }
  uint64_t requests() const { return requests_; }

 private:
  PartitionOptions options_;
  FrameSwitchRequesterInterface* requester_;
  bool started_ = false;
  uint64_t frame_id_ = 0;
  Eigen::Vector3d last_p_ = Eigen::Vector3d::Zero();
  double distance_ = 0.0;
  bool pending_ = false;
  Timestamp last_request_;
  uint64_t requests_ = 0;
};

}  // namespace cairn
