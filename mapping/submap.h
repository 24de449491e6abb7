#pragma once
// Submaps (thesis 5.1.2): a local frame of the filter with the point cloud and the occupancy tree
// aggregated in it. An OpenSubmap grows with every depth image; Finish() turns it into an
// immutable Submap that is shared (std::shared_ptr<const Submap>) with composition, matching and
// teammates.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "common/timestamp.h"
#include "mapping/mapping_options.h"
#include "mapping/occupancy_integrator.h"
#include "mapping/plane_extractor.h"
#include "mapping/submap_line.h"
#include "mapping/submap_plane.h"
#include "mapping/voxel_cloud.h"

namespace cairn {

struct SubmapMetadata {
  std::string robot;          // at most 255 bytes
  uint64_t id = 0;            // the filter's local frame id, unique per robot
  Timestamp start, end;       // first and last integrated image
  uint32_t images = 0;
  double distance = 0.0;      // m travelled in the frame
  SubmapOptions options;      // resolutions and log-odds the maps were made with
};

// What a submap holds beyond its cloud and tree: where its cameras were (one viewpoint per
// OpenSubmap::kViewpointSpacing of travel, the submap frame), its planar faces and its straight edges.
struct SubmapStructure {
  std::vector<Eigen::Vector3f> viewpoints;
  std::vector<SubmapPlane> planes;
  std::vector<SubmapLine> lines;
};

class Submap {
 public:
  Submap(SubmapMetadata metadata, std::vector<CloudPoint> points, std::unique_ptr<octomap::OcTree> tree,
         SubmapStructure structure = {});

  const SubmapMetadata& metadata() const { return metadata_; }
  const std::vector<CloudPoint>& points() const { return points_; }
  const octomap::OcTree& tree() const { return *tree_; }
  const SubmapStructure& structure() const { return structure_; }
  int64_t obstacle_points() const;
  // Heap held: the cloud and the octree's heap blocks.
  size_t memory_bytes() const;

 private:
  SubmapMetadata metadata_;
  std::vector<CloudPoint> points_;
  std::unique_ptr<const octomap::OcTree> tree_;
  size_t tree_bytes_ = 0;
  SubmapStructure structure_;
};

class OpenSubmap {
 public:
  OpenSubmap(const SubmapOptions& options, std::string robot, uint64_t id);

  // Adds one image's points (local frame, obstacle flags set) to the cloud and the voxel map.
  OccupancyUpdateStats Integrate(const CameraPoints& points, OccupancyIntegrator* integrator);
  void AddDistance(double d) { metadata_.distance += d; }

  // Viewpoints closer than this to the last one kept are not kept: the stereo error of a point
  // seen from either differs by a few per cent at the ranges submaps keep.
  static constexpr float kViewpointSpacing = 0.25f;

  // Inner nodes updated and the tree pruned; the open submap is left empty. With `planes`, the
  // planar faces are extracted; `lines` are its straight edges.
  std::shared_ptr<const Submap> Finish(PlaneExtractor* planes = nullptr, std::vector<SubmapLine> lines = {});
  // Starts over, empty, as submap `id`. The voxel table keeps its capacity: a new one per submap
  // (megabytes, freed while the finished submap's small blocks filled the heap around it) left
  // the heap fragmented, growing by about 5 MB per submap.
  void Restart(uint64_t id);

  const SubmapMetadata& metadata() const { return metadata_; }
  const VoxelCloud& cloud() const { return cloud_; }
  const octomap::OcTree& tree() const { return *tree_; }

 private:
  SubmapMetadata metadata_;
  VoxelCloud cloud_;
  VoxelCloud::Cells cells_;  // of the last image, for the integrator
  std::vector<Eigen::Vector3f> viewpoints_;
  std::unique_ptr<octomap::OcTree> tree_;
};

}  // namespace cairn
