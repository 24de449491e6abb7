#pragma once
// Keypoints of a submap for matching (thesis 6.1.1): the obstacle points, voxel-filtered to one
// centroid per voxel, less those whose descriptor sphere lies too much in unknown space of the
// submap's occupancy tree (a descriptor there would read unobserved space as empty space).

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <octomap/OcTree.h>

#include "common/options_visitor.h"
#include "mapping/submap.h"
#include "mapping/voxel_cloud.h"

namespace cairn {

struct KeypointExtractorOptions {
  double voxel_size = 0.1;      // m; one keypoint (centroid of obstacle points) per voxel
  double support_radius = 0.2;  // m; the descriptor sphere checked for known space
  // Share of the tree's voxels with centres in the sphere that must be known (occupied or free).
  double min_known_fraction = 0.8;

  void Visit(OptionsVisitor& v) {
    v.Number("voxel_size", voxel_size, 0.01, 10.0, "m");
    v.Number("support_radius", support_radius, 0.01, 10.0, "m");
    v.Number("min_known_fraction", min_known_fraction, 0.0, 1.0, "");
  }
};

struct SubmapKeypoints {
  std::vector<Eigen::Vector3f> points;  // submap frame, in voxel key order
  std::vector<float> known_fraction;    // of each kept keypoint's sphere
  int64_t non_finite_points = 0;        // input points skipped: non-finite or beyond +-100 km
  int64_t obstacle_points = 0;          // finite obstacle points used
  int64_t voxel_keypoints = 0;          // before the known-space filter
  int64_t dropped_unknown = 0;          // too little known space around them
};

class KeypointExtractor {
 public:
  explicit KeypointExtractor(const KeypointExtractorOptions& options = {}) : options_(options) {}

  const KeypointExtractorOptions& options() const { return options_; }

  // Voxel keypoints of the cloud, then the known-space filter on the submap's tree.
  SubmapKeypoints Extract(const Submap& submap) const;
  // Voxel keypoints of a cloud without any filter (known_fraction left empty).
  SubmapKeypoints VoxelKeypoints(const std::vector<CloudPoint>& points) const;
  // Share of the tree voxels whose centres lie within support_radius of `centre` that are known;
  // at least the voxel holding `centre` is sampled. 0 outside the tree's key range.
  double KnownFraction(const octomap::OcTree& tree, const Eigen::Vector3f& centre) const;

 private:
  KeypointExtractorOptions options_;
};

}  // namespace cairn
