#pragma once
// One submap's contribution to the composed map (thesis 5.2.2): its cloud moved by a pose and its
// occupancy tree resampled onto the global voxel grid. Each instance keeps its own scratch, so
// several threads can resample different submaps at once, one resampler each.

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <octomap/OcTree.h>

#include "mapping/voxel_cloud.h"
#include "mapping/voxel_hash_map.h"

namespace cairn {

class SubmapResampler {
 public:
  // `cloud`: the points moved by T_global_submap. `occupancy`: every global voxel the tree's
  // leaves cover (VoxelKey at the tree's resolution) with the mean log-odds of what lands in it.
  // An occupied finest voxel with cloud points in it is moved from the centroid of those points,
  // not from its centre: off the grid, a voxel goes to the global voxel its centre lands in, which
  // shifts a whole submap by up to half a voxel (about 5 cm, the same way for every voxel of a
  // submap moved by one pose), while the points say where in the voxel the surface is.
  void Resample(const octomap::OcTree& tree, const std::vector<CloudPoint>& points,
                const Eigen::Isometry3d& T_global_submap, std::vector<CloudPoint>* cloud,
                std::vector<std::pair<uint64_t, float>>* occupancy);

 private:
  struct Occ {
    float sum = 0.0f;  // weighted log-odds
    int32_t n = 0;     // total weight
  };
  // Weight of the samples of an occupied voxel moved by its points against 1 for any other sample:
  // enough that up to 8 free samples landing with them shift the mean by under 1 %.
  static constexpr int32_t kSurfaceWeight = 1 << 10;
  struct Leaf {
    Eigen::Vector3i min;  // lowest finest voxel, signed grid index
    int cells;            // finest voxels per side
    float value;
    bool occupied;
  };
  struct PointSum {
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();  // in voxel units, relative to the voxel corner
    int32_t n = 0;
  };
  std::vector<Leaf> leaves_;
  VoxelHashMap<PointSum> centroids_{1 << 14};  // per finest voxel of the tree
  std::vector<Occ> dense_;  // resampling grid over a moved submap's box, all zero between uses
  // Its cells in use and their global keys (computing a key back from a cell took three
  // divisions per voxel).
  std::vector<std::pair<uint32_t, uint64_t>> touched_;
  VoxelHashMap<Occ> resample_{1 << 16};  // samples outside the dense grid
};

}  // namespace cairn
