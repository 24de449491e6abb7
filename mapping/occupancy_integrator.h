#pragma once
// Integrates one depth image into an OctoMap occupancy tree (thesis 5.1.2, eqs. 5.8, 5.9) with the
// semantics of OctoMap's insertPointCloud with discretization: each endpoint voxel is hit once,
// one ray is cast from the sensor to the centre of each distinct endpoint voxel (instead of one per
// pixel), every voxel is updated at most once per image and occupied wins over free. What makes it
// fast is bookkeeping, not different results: a dense generation-stamped cube around the camera
// replaces OctoMap's hash sets, so deduplicating a voxel costs one array access, and the tree is
// updated lazily (inner nodes once when the submap is finished).

#include <cstdint>
#include <memory>
#include <vector>

#include <octomap/OcTree.h>

#include "mapping/depth_image.h"
#include "mapping/mapping_options.h"
#include "mapping/voxel_cloud.h"
#include "mapping/voxel_hash_map.h"

namespace cairn {

// OctoMap's key of coordinate 0 at its depth of 16 (OcTreeBaseImpl::tree_max_val): key = floor(x /
// resolution) + kOctreeKeyOrigin, valid in [0, 2 kOctreeKeyOrigin).
inline constexpr int kOctreeKeyOrigin = 1 << 15;

// A tree configured with the submap options' resolution, log-odds and clamping.
std::unique_ptr<octomap::OcTree> MakeOccupancyTree(const SubmapOptions& options);

struct OccupancyUpdateStats {
  int64_t occupied = 0;  // voxels updated as occupied
  int64_t free = 0;      // voxels updated as free
  int64_t rays = 0;
};

class OccupancyIntegrator {
 public:
  // `max_distance` bounds the distance of endpoints from the camera (sizes the dense cube; voxels
  // beyond it still work through a slower hash map).
  OccupancyIntegrator(double resolution, double max_distance);

  // Adds the points (local frame, already filtered by range) and the free-only ray ends.
  OccupancyUpdateStats Integrate(const CameraPoints& points, octomap::OcTree* tree);
  // The same update from the cells VoxelCloud::AddBatch found for these points (cloud inverse
  // resolution `cloud_inv_resolution`), without a pass over the points: when the cloud's
  // resolution is exactly half the tree's (0.05 m and 0.1 m), every tree voxel with a point strictly
  // inside a cloud cell is that cell's parent. Other resolutions fall back to Integrate.
  OccupancyUpdateStats IntegrateCells(const CameraPoints& points, const VoxelCloud::Cells& cells,
                                      float cloud_inv_resolution, octomap::OcTree* tree);

 private:
  // Starts an image; false when the camera is outside the tree's key range.
  bool Begin(const CameraPoints& points, octomap::OcTree* tree);
  // Marks a tree key (OcTreeKey values) / the voxel of a point occupied, once per image.
  void MarkOccupied(int kx, int ky, int kz);
  void MarkPoint(const Eigen::Vector3f& p);
  // Rays to the occupied voxels and the far ends, then the tree's leaves.
  OccupancyUpdateStats CastAndUpdate(const CameraPoints& points, octomap::OcTree* tree);
  uint32_t& Stamp(const octomap::OcTreeKey& k);

  double factor_ = 0.0;  // the tree's resolution_factor
  octomap::point3d origin_;
  int side_ = 0;
  octomap::OcTreeKey centre_;
  std::vector<uint32_t> stamps_;
  VoxelHashMap<uint32_t> overflow_;
  uint32_t generation_ = 0;
  std::vector<octomap::OcTreeKey> occupied_, free_;
  VoxelHashMap<uint8_t> far_seen_;
  // Keys (x | y << 16 | z << 32) marked occupied recently in this image, direct mapped.
  static constexpr int kRecentBits = 12;
  static constexpr uint64_t kNoKey = ~uint64_t{0};
  std::vector<uint64_t> recent_ = std::vector<uint64_t>(size_t{1} << kRecentBits, kNoKey);
  octomap::KeyRay ray_;
};

}  // namespace cairn
