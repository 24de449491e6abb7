#include "mapping/local_mapper.h"

#include <algorithm>
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

// Drops the points whose depth error exceeds `max_error`, in place and keeping the others' order;
// each becomes the end of a free-space ray its depth error short of it. Returns how many.
size_t DropInaccurate(float max_error, CameraPoints* pts) {
  const Eigen::Vector3f origin = pts->T_local_cam.translation().cast<float>();
  size_t kept = 0;
  for (size_t i = 0; i < pts->size(); ++i) {
    const float e = pts->depth_error[i];
    if (e > max_error) {
      const float reach = std::max(0.0f, 1.0f - e / pts->p_cam[i].z());
      pts->far_local.push_back(origin + reach * (pts->p_local[i] - origin));
      continue;
    }
    pts->MovePoint(i, kept++);
  }
  const size_t dropped = pts->size() - kept;
  pts->Truncate(kept);
  return dropped;
}

}  // namespace

LocalMapper::LocalMapper(const MappingOptions& options, const StereoCamera& camera, std::string robot,
                         FrameSwitchRequesterInterface* requester)
    : options_(options),
      robot_(std::move(robot)),
      projector_(options.depth, camera),
      fusion_(options.fusion, camera, projector_.error_model()),
      classifier_(options.obstacles, camera, projector_.error_model(), projector_.range()),
      integrator_(options.submap.octree_resolution, MaxDistance(camera, projector_.range())),
      planes_(options.planes, projector_.error_model()),
      lines_(options.lines.fusion),
      rolling_(options.rolling_map),
      partitioner_(options.partition, requester),
      open_(std::make_unique<OpenSubmap>(options.submap, robot_, 0)) {}

std::shared_ptr<const Submap> LocalMapper::FinishAndStart(uint64_t new_frame_id) {
  std::shared_ptr<const Submap> done;
  if (open_->metadata().images > 0) {
    done = open_->Finish(options_.planes.enabled ? &planes_ : nullptr,
                         options_.lines.enabled ? lines_.Lines() : std::vector<SubmapLine>{});
    ++stats_.submaps_finished;
  }
  open_->Restart(new_frame_id);
  lines_.Reset();
  return done;
}

Status LocalMapper::Process(const DepthImage& image, const MappingPose& pose) {
  if (!pose.T_local_body.matrix().allFinite()) return InvalidArgumentError("mapping pose is not finite");
  if (!started_) {
    started_ = true;
    open_->Restart(pose.frame_id);
  } else if (pose.frame_id != open_->metadata().id) {
    // The frame changed without OnFrameSwitch: the transform is unknown, so the rolling map starts
    // over; the submap is finished all the same.
    ++stats_.unannounced_frame_changes;
    finished_ = FinishAndStart(pose.frame_id);
    rolling_.Clear();
    fusion_.Reset();
  }
  const DepthImage* depth = &image;
  std::span<const float> depth_error;
  if (options_.fusion.enabled) {
    CAIRN_RETURN_IF_ERROR(fusion_.Fuse(image, pose.T_local_body * projector_.camera().T_body_cam));
    depth = &fusion_.fused();
    depth_error = fusion_.depth_error();
    stats_.fused_pixels += fusion_.stats().fused;
  }
  CAIRN_RETURN_IF_ERROR(projector_.Project(*depth, pose.T_local_body, &points_, depth_error));
  // The classifier sees the fused depths but keeps eq. 5.4's single-image errors in its step
  // thresholds, with which its recall was measured: the fused sigma assumes independent images,
  // which stereo on the same texture from nearby poses is not entirely.
  CAIRN_RETURN_IF_ERROR(classifier_.Classify(*depth, &points_, &obstacles_));
  const Eigen::Vector3d body = pose.T_local_body.translation();
  rolling_.Recenter(body.head<2>());
  rolling_.Integrate(obstacles_.cells);
  if (open_->metadata().images > 0) open_->AddDistance((body - last_body_).norm());
  last_body_ = body;
  stats_.points += static_cast<int64_t>(points_.size());
  if (options_.depth.max_map_error > 0.0) {
    stats_.unmapped_points +=
        static_cast<int64_t>(DropInaccurate(static_cast<float>(options_.depth.max_map_error), &points_));
  }
  open_->Integrate(points_, &integrator_);
  if (options_.lines.enabled) {
    const Eigen::Isometry3d T_local_cam = pose.T_local_body * projector_.camera().T_body_cam;
    for (const LineSighting& s : image.lines)
      stats_.line_sightings += lines_.Add(s.Transformed(T_local_cam)) ? 1 : 0;
  }
  partitioner_.Update(pose.time, pose.frame_id, body, pose.position_covariance);
  ++stats_.images;
  stats_.obstacle_points += obstacles_.obstacle_points;
  return Status::Ok();
}

std::shared_ptr<const Submap> LocalMapper::OnFrameSwitch(uint64_t new_frame_id, const Eigen::Isometry3d& T_old_new) {
  last_body_ = T_old_new.inverse() * last_body_;
  rolling_.Rebase(T_old_new, last_body_.head<2>());
  fusion_.Rebase(T_old_new);
  auto done = FinishAndStart(new_frame_id);
  started_ = true;
  return done;
}

std::shared_ptr<const Submap> LocalMapper::FinishOpenSubmap() { return FinishAndStart(open_->metadata().id); }

std::shared_ptr<const Submap> LocalMapper::TakeFinished() { return std::exchange(finished_, nullptr); }

}  // namespace cairn
