#pragma once
// What the daemon estimated, as Foxglove's well-known protobuf schemas: the filter's body pose per
// camera frame (foxglove.PoseInFrame on /pose and the map -> body transform on /tf), finished
// submaps (foxglove.PointCloud on /map/submaps, placed by the submap origin) and the rolling
// obstacle map (foxglove.Grid on /map/obstacles). Frames: "map" is the robot's first local frame
// (trajectory.tum's), "body" the IMU body.

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/timestamp.h"
#include "mapping/grid_map.h"
#include "mapping/voxel_cloud.h"

namespace cairn {

class EstimateEncoder {
 public:
  static constexpr const char* kMapFrame = "map";
  static constexpr const char* kBodyFrame = "body";

  // Each returns the encoded message, valid until the next call of the same method.
  const std::string& Pose(Timestamp time, const Eigen::Isometry3d& T_map_body);
  const std::string& Transform(Timestamp time, const Eigen::Isometry3d& T_map_body);
  // Points in the submap frame; x, y, z (float32), intensity and obstacle (uint8) per point.
  const std::string& Cloud(Timestamp time, const Eigen::Isometry3d& T_map_submap, const std::vector<CloudPoint>& points);
  // One float32 traversability per cell (NaN unknown, > 1 untraversable); T_map_local places the
  // grid's local frame, the grid's own origin is added, at the body height `z`.
  const std::string& Grid(Timestamp time, const Eigen::Isometry3d& T_map_local, double z, const GridMap& grid);

 private:
  std::string pose_, transform_, cloud_, grid_;
};

}  // namespace cairn
