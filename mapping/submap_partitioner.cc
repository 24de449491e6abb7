#include "mapping/submap_partitioner.h"

#include <algorithm>
#include <cmath>

#include "estimation/math/symmetric_eigen.h"

namespace cairn {

SubmapPartitioner::SubmapPartitioner(const PartitionOptions& options, FrameSwitchRequesterInterface* requester)
    : options_(options), requester_(requester) {}

bool SubmapPartitioner::Update(Timestamp time, uint64_t frame_id, const Eigen::Vector3d& p,
                               const Eigen::Matrix3d& cov) {
  if (!started_ || frame_id != frame_id_) {
    started_ = true;
    frame_id_ = frame_id;
    last_p_ = p;
    distance_ = 0.0;
    pending_ = false;
  }
  if (p.allFinite()) {
    distance_ += (p - last_p_).norm();
    last_p_ = p;
  }
  // Largest standard deviation over all directions (covariance symmetrized first).
  const Eigen::Matrix3d sym = 0.5 * (cov + cov.transpose());
  const double sigma = sym.allFinite()
                           ? std::sqrt(std::max(0.0, SymmetricEigenvalues(sym).maxCoeff()))
                           : 0.0;
  const bool by_sigma = sigma > options_.max_position_sigma;
  const bool by_distance = distance_ > options_.max_distance;
  if (!by_sigma && !by_distance) return false;
  if (pending_ && (time - last_request_).seconds() < options_.retry_interval) return false;
  FrameSwitchRequest r;
  r.time = time;
  r.frame_id = frame_id;
  r.reason = by_sigma ? PartitionReason::kPositionSigma : PartitionReason::kDistance;
  r.position_sigma = sigma;
  r.distance = distance_;
  pending_ = true;
  last_request_ = time;
  ++requests_;
  requester_->RequestFrameSwitch(r);
  return true;
}

}  // namespace cairn
