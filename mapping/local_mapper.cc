#include "mapping/local_mapper.h"

#include <cmath>
#include <utility>

namespace cairn {
namespace {

// Farthest camera-frame distance of a point with depth <= range: the image corner's ray.
double MaxDistance(const StereoCamera& c, double range) {
  const PinholeRadTan& k = c.intrinsics;
  const double ax = std::max(k.cx, k.width - k.cx) / k.fx, ay = std::max(k.cy, k.height - k.cy) / k.fy;
  return range * std::sqrt(1.0 + ax * ax + ay * ay);
}

}  // namespace

LocalMapper::LocalMapper(const MappingOptions& options, const StereoCamera& camera, std::string robot,
                         FrameSwitchRequesterInterface* requester)
    : options_(options),
      robot_(std::move(robot)),
      projector_(options.depth, camera),
      classifier_(options.obstacles, camera, projector_.error_model(), projector_.range()),
      integrator_(options.submap.octree_resolution, MaxDistance(camera, projector_.range())),
      rolling_(options.rolling_map),
      partitioner_(options.partition, requester),
      open_(std::make_unique<OpenSubmap>(options.submap, robot_, 0)) {}

std::shared_ptr<const Submap> LocalMapper::FinishAndStart(uint64_t new_frame_id) {
  std::shared_ptr<const Submap> done;
  if (open_->metadata().images > 0) {
    done = open_->Finish();
    ++stats_.submaps_finished;
  }
  open_ = std::make_unique<OpenSubmap>(options_.submap, robot_, new_frame_id);
  return done;
}

Status LocalMapper::Process(const DepthImage& image, const MappingPose& pose) {
  if (!pose.T_local_body.matrix().allFinite()) return InvalidArgumentError("mapping pose is not finite");
  if (!started_) {
    started_ = true;
    open_ = std::make_unique<OpenSubmap>(options_.submap, robot_, pose.frame_id);
  } else if (pose.frame_id != open_->metadata().id) {
    // The frame changed without OnFrameSwitch: the transform is unknown, so the rolling map starts
    // over; the submap is finished all the same.
    ++stats_.unannounced_frame_changes;
    finished_ = FinishAndStart(pose.frame_id);
    rolling_.Clear();
  }
  CAIRN_RETURN_IF_ERROR(projector_.Project(image, pose.T_local_body, &points_));
  CAIRN_RETURN_IF_ERROR(classifier_.Classify(image, &points_, &obstacles_));
  const Eigen::Vector3d body = pose.T_local_body.translation();
  rolling_.Recenter(body.head<2>());
  rolling_.Integrate(obstacles_.cells);
  if (open_->metadata().images > 0) open_->AddDistance((body - last_body_).norm());
  last_body_ = body;
  open_->Integrate(points_, &integrator_);
  partitioner_.Update(pose.time, pose.frame_id, body, pose.position_covariance);
  ++stats_.images;
  stats_.points += static_cast<int64_t>(points_.size());
  stats_.obstacle_points += obstacles_.obstacle_points;
  return Status::Ok();
}

std::shared_ptr<const Submap> LocalMapper::OnFrameSwitch(uint64_t new_frame_id, const Eigen::Isometry3d& T_old_new) {
  last_body_ = T_old_new.inverse() * last_body_;
  rolling_.Rebase(T_old_new, last_body_.head<2>());
  auto done = FinishAndStart(new_frame_id);
  started_ = true;
  return done;
}

std::shared_ptr<const Submap> LocalMapper::FinishOpenSubmap() { return FinishAndStart(open_->metadata().id); }

std::shared_ptr<const Submap> LocalMapper::TakeFinished() { return std::exchange(finished_, nullptr); }

}  // namespace cairn
