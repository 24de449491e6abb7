#pragma once
// Global map composition (thesis 5.2.2): every submap's cloud and occupancy tree moved by its
// latest graph pose and merged, the clouds by concatenation and a voxel-centroid filter, the trees
// by resampling each onto the global grid and summing log-odds with clamping.
//
// Each finished submap's transformed contribution is cached with the pose it was made for; a
// change of that pose beyond the thresholds takes exactly that contribution out of the running
// sums and puts the new one in, everything else is untouched. To make taking out exact, the
// log-odds are summed unclamped and clamped once when read, which also makes the result
// independent of merge order (the thesis notes sequential clamping is not). The robot's own open
// submap is never cached: it is merged afresh on every Update().

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <octomap/OcTree.h>

#include "common/status.h"
#include "mapping/mapping_options.h"
#include "mapping/submap.h"
#include "mapping/submap_resampler.h"
#include "mapping/voxel_cloud.h"
#include "mapping/voxel_hash_map.h"

namespace cairn {

struct SubmapRef {
  std::string robot;
  uint64_t id = 0;
  auto operator<=>(const SubmapRef&) const = default;
};

struct CompositionStats {
  int rebuilt = 0;        // cached contributions recomputed (pose change or new)
  int removed = 0;
  int cached = 0;         // reused unchanged
  int64_t voxels = 0;     // known occupancy voxels in the cache
};

class MapComposer {
 public:
  // Clamping bounds and the octree resolution come from `submap`; all submaps must share it.
  MapComposer(const CompositionOptions& options, const SubmapOptions& submap);

  // Adds a finished submap or moves one already known (to be applied by Update()).
  Status SetSubmap(std::shared_ptr<const Submap> submap, const Eigen::Isometry3d& T_global_submap);
  Status SetPose(const SubmapRef& ref, const Eigen::Isometry3d& T_global_submap);
  void RemoveSubmap(const SubmapRef& ref);
  // The robot's own growing submap (not owned; nullptr clears it).
  void SetOpenSubmap(const OpenSubmap* open, const Eigen::Isometry3d& T_global_submap);

  // Applies pose changes above the thresholds and re-merges the open submap.
  CompositionStats Update();
  // Drops the cache and rebuilds every contribution.
  CompositionStats Rebuild();

  // The composed maps (finished submaps from the cache plus the open submap).
  std::vector<CloudPoint> Cloud() const;
  std::unique_ptr<octomap::OcTree> Octree() const;
  // Clamped log-odds of the global voxel containing `p`; NaN when unknown.
  float LogOdds(const Eigen::Vector3d& p) const;

  size_t submap_count() const { return entries_.size(); }
  // Bytes held beyond the submaps themselves: the cached contributions and the composed tables.
  size_t memory_bytes() const;
  // Bytes of the submaps it holds (their clouds and octrees).
  size_t submap_bytes() const;

 private:
  struct Occ {
    float sum = 0.0f;
    int32_t n = 0;
  };
  struct Entry {
    std::shared_ptr<const Submap> submap;
    Eigen::Isometry3d pose_target = Eigen::Isometry3d::Identity();  // latest pose given
    Eigen::Isometry3d pose_applied = Eigen::Isometry3d::Identity(); // pose of the cached contribution
    bool applied = false;
    std::vector<CloudPoint> cloud;                      // transformed points
    std::vector<std::pair<uint64_t, float>> occupancy;  // global voxel, resampled log-odds
  };
  bool Moved(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) const;
  void Apply(const Entry& e, int sign);
  float Clamp(float v) const;

  CompositionOptions options_;
  SubmapOptions submap_options_;
  std::map<SubmapRef, Entry> entries_;
  VoxelCloud cloud_;
  VoxelHashMap<Occ> occupancy_;
  int64_t known_voxels_ = 0;  // entries of occupancy_ with n > 0
  // The open submap's merged contribution, rebuilt on each Update().
  const OpenSubmap* open_ = nullptr;
  Eigen::Isometry3d open_pose_ = Eigen::Isometry3d::Identity();
  VoxelCloud open_cloud_;
  VoxelHashMap<float> open_occupancy_;
  SubmapResampler resampler_;
  std::vector<CloudPoint> open_points_;
  std::vector<std::pair<uint64_t, float>> open_pairs_;
};

}  // namespace cairn
