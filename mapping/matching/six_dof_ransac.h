#pragma once
// The 6-DoF variant of the matcher's initial alignment (four_dof_ransac.h): RANSAC without the
// gravity direction, whose minimal set is three correspondences, solved by the closed-form
// least-squares rotation of the centred points (Kabsch, by SVD). It exists to measure what gravity
// buys the matcher (thesis 6.1).
//
// The options are FourDofRansacOptions, read in 3-D: a sample is degenerate, and skipped, when two
// of its points are closer than min_horizontal_separation (3-D distance) in either submap, when
// its third point lies within half that of the line through the other two (no rotation about that
// line), or when any of its three side lengths differs between the submaps by more than
// max_pair_length_difference (no rigid motion maps one onto the other). Sampling is deterministic
// as there; the best hypothesis is refined by least squares on its inliers while that does not
// lose any.

#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/status.h"
#include "mapping/matching/four_dof_ransac.h"

namespace cairn {

struct SixDofRansacResult {
  Eigen::Isometry3d T_a_b = Eigen::Isometry3d::Identity();  // source (B) points onto target (A)
  std::vector<size_t> inliers;  // indices into the correspondences, increasing
  double inlier_rms = 0.0;      // m
  int64_t iterations = 0;       // samples drawn
  int64_t degenerate_samples = 0;
  size_t skipped_non_finite = 0;
};

class SixDofRansac {
 public:
  explicit SixDofRansac(const FourDofRansacOptions& options = {}) : options_(options) {}

  // As FourDofRansac::Estimate, with three correspondences needed at least.
  Expected<SixDofRansacResult> Estimate(std::span<const Eigen::Vector3d> source_b,
                                        std::span<const Eigen::Vector3d> target_a) const;

  // The minimal solver with the degeneracy checks above.
  std::optional<Eigen::Isometry3d> SolveThreePoint(const Eigen::Vector3d (&source)[3],
                                                   const Eigen::Vector3d (&target)[3]) const;

  // Least-squares rigid fit to the correspondences `indices`; nothing for fewer than three or
  // collinear points.
  static std::optional<Eigen::Isometry3d> FitLeastSquares(std::span<const Eigen::Vector3d> source_b,
                                                          std::span<const Eigen::Vector3d> target_a,
                                                          std::span<const size_t> indices);

 private:
  FourDofRansacOptions options_;
};

}  // namespace cairn
