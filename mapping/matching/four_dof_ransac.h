#pragma once
// Initial alignment of two gravity-aligned submaps from point correspondences (thesis 6.1.2,
// eqs. 6.5 to 6.7): RANSAC whose minimal set is two correspondences plus the shared gravity
// direction, so every hypothesis has roll = pitch = 0 and only x, y, z and yaw are estimated.
//
// A hypothesis from pairs (p_0, q_0) in submap A and (p_1, q_1) in submap B: the horizontal parts
// of q_i - p_i fix the yaw (eqs. 6.5, 6.6: the rotation taking B's horizontal pair direction onto
// A's), the midpoints fix the translation (eq. 6.7: t = mean_A - R mean_B). A pair is degenerate,
// and skipped, when its points are too close horizontally in either submap (no direction) or when
// its horizontal length or height difference disagrees between the submaps (no 4-DoF motion maps
// one onto the other, so at least one of the two correspondences is wrong).
//
// Sampling is deterministic: one std::mt19937_64 seeded with `seed` per call, indices drawn by
// rejection (no std::uniform_int_distribution, whose output differs between standard libraries)
// in a fixed order. The best hypothesis (most inliers, then the least sum of squared inlier
// distances) is refined by a least-squares 4-DoF fit to its inliers while that does not lose any.

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "common/options_visitor.h"
#include "common/status.h"
#include "mapping/matching/four_dof_transform.h"

namespace cairn {

struct FourDofRansacOptions {
  double inlier_threshold = 0.1;            // m; 3-D distance |T_a_b * source - target|
  double min_horizontal_separation = 0.3;   // m; of the two points of a sample, in both submaps
  double max_pair_length_difference = 0.1;  // m; horizontal length and height difference of a sample
  int64_t max_iterations = 2000;            // samples drawn at most, degenerate ones included
  double confidence = 0.999;                // of having drawn one all-inlier sample (adaptive stop)
  int64_t min_inliers = 3;                  // consensus below this is a failure
  uint64_t seed = 1;
  int64_t refine_rounds = 3;  // least-squares refits on the inliers; 0: the minimal solution as is

  void Visit(OptionsVisitor& v) {
    v.Number("inlier_threshold", inlier_threshold, 1e-4, 10.0, "m");
    v.Number("min_horizontal_separation", min_horizontal_separation, 0.0, 100.0, "m");
    v.Number("max_pair_length_difference", max_pair_length_difference, 0.0, 10.0, "m");
    v.Integer("max_iterations", max_iterations, 1, 10'000'000, "");
    v.Number("confidence", confidence, 0.5, 0.999999, "");
    v.Integer("min_inliers", min_inliers, 2, 1'000'000, "");
    v.Integer("seed", seed, 0, INT64_MAX, "");
    v.Integer("refine_rounds", refine_rounds, 0, 100, "");
  }
  Status Validate() const;
};

struct FourDofRansacResult {
  FourDofTransform T_a_b;       // maps source (submap B) points onto target (submap A) points
  std::vector<size_t> inliers;  // indices into the correspondences, increasing
  double inlier_rms = 0.0;      // m; RMS 3-D distance of the inliers
  int64_t iterations = 0;       // samples drawn
  int64_t degenerate_samples = 0;
  size_t skipped_non_finite = 0;  // correspondences with a non-finite coordinate, never used
};

class FourDofRansac {
 public:
  explicit FourDofRansac(const FourDofRansacOptions& options = {}) : options_(options) {}

  // Correspondence i is source_b[i] (submap B, its gravity-aligned frame) <-> target_a[i] (submap
  // A). Fails with kInvalidArgument for bad options or spans of different sizes, kFailedPrecondition
  // for fewer finite correspondences than max(2, min_inliers), kNotFound when no hypothesis reaches
  // min_inliers (no consensus, or every sample degenerate).
  Expected<FourDofRansacResult> Estimate(std::span<const Eigen::Vector3d> source_b,
                                         std::span<const Eigen::Vector3d> target_a) const;

  // The minimal solver, eqs. 6.5 to 6.7, with the degeneracy checks above: T_a_b with
  // T_a_b * source[i] ~ target[i] for i = 0, 1, or nothing for a degenerate pair.
  std::optional<FourDofTransform> SolveTwoPoint(const Eigen::Vector3d& source0,
                                                const Eigen::Vector3d& source1,
                                                const Eigen::Vector3d& target0,
                                                const Eigen::Vector3d& target1) const;

  // Least-squares 4-DoF fit (closed form: yaw from the centred horizontal coordinates, then the
  // translation from the centroids) to the correspondences `indices`; nothing for fewer than two
  // or when the horizontal spread leaves the yaw undefined.
  static std::optional<FourDofTransform> FitLeastSquares(std::span<const Eigen::Vector3d> source_b,
                                                         std::span<const Eigen::Vector3d> target_a,
                                                         std::span<const size_t> indices);

 private:
  FourDofRansacOptions options_;
};

}  // namespace cairn
