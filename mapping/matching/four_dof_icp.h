#pragma once
// Refinement of a submap match (thesis 6.1.2, "Refinement: ICP Optimization"): point-to-plane ICP
// on the full clouds that moves the source cloud (submap B, its gravity-aligned frame) onto the
// target cloud (submap A) over x, y, z and yaw only, so roll and pitch stay zero throughout.
//
// Per iteration: each finite source point p, moved by the current T_a_b to q = R(yaw) p + t, is
// paired with its nearest target point a (k-d tree, nanoflann). The pair is kept when |q - a| is
// within the gate (max_correspondence_distance, shrunk by gate_shrink per iteration down to
// min_correspondence_distance) and a has a good normal n: local PCA over the normal_neighbours
// nearest target points within normal_radius, at least min_normal_neighbours of them, flat
// (smallest eigenvalue / sum <= max_surface_variation) and not a line (middle / largest >=
// min_planar_ratio). With unique_targets a target point keeps only its closest source point, so
// no two residuals share one target point's noise, as the covariance below assumes (in the tests, shared
// target points raised the mean normalized error squared from 5.0 to 6.7). One Gauss-Newton step on the
// residuals r = n . (q - a), with the Jacobian
//   dr/d(x, y, z) = n,   dr/d(yaw) = n . (z x (q - t)),
// updates (x, y, z, yaw) additively. Converged, once the gate is at its minimum: a step below
// translation_tolerance and yaw_tolerance, or below max_step_sigmas standard deviations of the
// estimate (noise-free clouds need the first, noisy ones the second). Near the optimum the pairs
// can cycle through a few sets, moving the estimate by a fraction of its standard deviation for
// ever; after freeze_after passes at the gate's minimum the pairs are kept as they are, and
// Gauss-Newton converges on them (the final pass then uses them too).
//
// Covariance (x, y, z, yaw) of the result, in the order of FourDofTransform::ToVector(), the
// translation in A's frame, yaw in rad (about A's z axis through A's origin, so far from the
// origin yaw and translation are correlated): after convergence one more pass at the final
// T_a_b builds the correspondence set (the frozen one, if frozen) again, and
//   Sigma = sigma^2 (J^T J)^-1,   sigma^2 = sum_i r_i^2 / (n - 4),
// with J the n x 4 Jacobian above and r_i the point-to-plane residuals of those n pairs. It
// assumes independent residuals of one variance and correct pairs; errors of the normals, edges
// and curved surfaces are not in it (on the test scene with 1 cm noise the mean normalized error
// squared is about 5 where 4 is exact). (The thesis takes the RMSE of the final point-to-point
// distances; here it is the point-to-plane residual, the one minimized.)
//
// Observability: J^T J re-expressed with yaw about the centroid c of the paired points
// (dr/d(yaw) = n . (z x (q - c))), the yaw scaled by their RMS horizontal distance from c and the
// whole divided by n. Its smallest eigenvalue is dimensionless: the mean squared residual change
// for the weakest unit motion (1 m, or 1 m of arc at that distance). Below min_observability the
// geometry is degenerate (a flat plane leaves x, y and yaw free, a single wall the motion along
// it) and the alignment fails instead of following the noise. The default, 0.001 (about 3 cm of
// RMS residual change per metre), lets rolling ground of a few percent slope through: over the
// thousands of pairs of a submap it pins the pose to millimetres, and simulated submaps that
// revisit a place matched within 3 cm where 0.005 had refused them.
//
// Points with a non-finite coordinate are skipped and counted. Nothing is allocated per iteration.

#include <span>

#include <Eigen/Core>

#include "mapping/matching/four_dof_transform.h"
#include "mapping/matching/icp_options.h"
#include "mapping/matching/point_to_plane_icp.h"

namespace cairn {

// Covariance (x, y, z, yaw), as above.
using FourDofIcpResult = IcpOutcome<FourDofTransform, 4>;

class FourDofIcp {
 public:
  explicit FourDofIcp(const IcpOptions& options = {}) : options_(options) {}

  // Aligns `source_b` (submap B's cloud, B's frame) to `target_a` (submap A's cloud, A's frame)
  // starting from `T_a_b_initial`.
  FourDofIcpResult Align(std::span<const Eigen::Vector3d> target_a, std::span<const Eigen::Vector3d> source_b,
                         const FourDofTransform& T_a_b_initial) const;

 private:
  IcpOptions options_;
};

}  // namespace cairn
