#pragma once
// Whether two submaps' grey levels agree under a candidate alignment: the normalized
// cross-correlation of the grey level of each of B's points, moved by T_a_b, with that of A's
// points in the same voxel. On smooth ground, geometry alone cannot tell a true alignment from
// one that slides along a ridge or turns about a crater's rim (their keypoints and ICP residuals
// look alike); the ground's albedo pattern can. The correlation ignores the gain and offset by
// which two cameras or exposures differ.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "mapping/matching/four_dof_transform.h"
#include "mapping/voxel_hash_map.h"

namespace cairn {

struct PhotometricScore {
  size_t pairs = 0;  // B's points that fell into a voxel of A's
  // NCC over those pairs, in [-1, 1]; NaN with fewer than 2 pairs or without texture on one side.
  double ncc = std::numeric_limits<double>::quiet_NaN();
};

class PhotometricAgreement {
 public:
  // A's cloud and each point's grey level (same length; the shorter decides), hashed at `voxel` m.
  PhotometricAgreement(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& grey, double voxel);

  // B's cloud and grey levels under T_a_b.
  PhotometricScore Score(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& grey,
                         const FourDofTransform& T_a_b) const;
  PhotometricScore Score(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& grey,
                         const Eigen::Isometry3d& T_a_b) const;

  // x, y and yaw of `start` moved to where B's grey levels correlate best with A's, by a pattern
  // search from steps of `step_translation` and `step_yaw` (yaw about the overlap's centre) halved
  // down to a tenth (z is kept):
  // where the ground is smooth, the ICP leaves yaw and the slide along a rim to chance, which the
  // albedo pattern pins down. At most `max_scores` scores; `best`, if given, gets the final one.
  FourDofTransform Refine(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& grey,
                          const FourDofTransform& start, double step_translation, double step_yaw,
                          int max_scores, PhotometricScore* best) const;

 private:
  float inverse_voxel_ = 20.0f;
  struct Cell {
    float sum = 0.0f;
    uint32_t count = 0;
  };
  VoxelHashMap<Cell> cells_;
};

}  // namespace cairn
