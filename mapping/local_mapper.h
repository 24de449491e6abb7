#pragma once
// The mapping stage for one stereo camera (thesis 5.1), as the daemon's mapping executor drives it:
// per depth image, points with errors, obstacle classification, the rolling obstacle map and the
// open submap; the partition policy asks the filter for frame switches, and the filter's switch
// finishes the open submap. Not thread safe: one mapping thread owns it.

#include <memory>
#include <string>

#include <Eigen/Geometry>

#include "mapping/depth_fusion.h"
#include "mapping/depth_projector.h"
#include "mapping/frame_switch_requester_interface.h"
#include "mapping/obstacle_classifier.h"
#include "mapping/occupancy_integrator.h"
#include "mapping/rolling_obstacle_map.h"
#include "mapping/submap.h"
#include "mapping/submap_line_fuser.h"
#include "mapping/submap_partitioner.h"

namespace cairn {

// The filter's estimate at an image's exposure (LocalReferenceFilter::PoseAt).
struct MappingPose {
  Timestamp time;
  uint64_t frame_id = 0;
  Eigen::Isometry3d T_local_body = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d position_covariance = Eigen::Matrix3d::Zero();
};

struct LocalMapperStats {
  int64_t images = 0;
  int64_t points = 0;
  int64_t fused_pixels = 0;  // pixels averaged with earlier images (mapping.fusion)
  int64_t unmapped_points = 0;  // points beyond depth.max_map_error: free space only
  int64_t obstacle_points = 0;
  int64_t submaps_finished = 0;
  int64_t unannounced_frame_changes = 0;  // poses in a new frame without OnFrameSwitch
  int64_t line_sightings = 0;             // edges seen in images that joined or started a submap edge
};

class LocalMapper {
 public:
  LocalMapper(const MappingOptions& options, const StereoCamera& camera, std::string robot,
              FrameSwitchRequesterInterface* requester);

  // One depth image and the pose at its exposure.
  Status Process(const DepthImage& image, const MappingPose& pose);
  // The filter switched from the open submap's frame to `new_frame_id` (T_old_new from its
  // FrameSwitchResult). Returns the finished submap (nullptr if it saw no image).
  std::shared_ptr<const Submap> OnFrameSwitch(uint64_t new_frame_id, const Eigen::Isometry3d& T_old_new);
  // End of a run: the open submap finished as it is (nullptr if it saw no image); an empty one
  // in the same frame takes its place.
  std::shared_ptr<const Submap> FinishOpenSubmap();

  const RollingObstacleMap& obstacle_map() const { return rolling_; }
  const OpenSubmap& open_submap() const { return *open_; }
  const ObstacleResult& last_obstacles() const { return obstacles_; }
  const LocalMapperStats& stats() const { return stats_; }
  // Finished submaps not yet taken (unannounced frame changes finish one inside Process).
  std::shared_ptr<const Submap> TakeFinished();

 private:
  std::shared_ptr<const Submap> FinishAndStart(uint64_t new_frame_id);

  MappingOptions options_;
  std::string robot_;
  DepthProjector projector_;
  DepthFusion fusion_;
  ObstacleClassifier classifier_;
  OccupancyIntegrator integrator_;
  PlaneExtractor planes_;
  SubmapLineFuser lines_;
  RollingObstacleMap rolling_;
  SubmapPartitioner partitioner_;
  std::unique_ptr<OpenSubmap> open_;
  bool started_ = false;
  Eigen::Vector3d last_body_ = Eigen::Vector3d::Zero();
  CameraPoints points_;
  ObstacleResult obstacles_;
  std::shared_ptr<const Submap> finished_;
  LocalMapperStats stats_;
};

}  // namespace cairn
