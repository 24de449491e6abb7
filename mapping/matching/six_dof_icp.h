#pragma once
// The 6-DoF variant of the matcher's refinement (four_dof_icp.h): the same point-to-plane ICP,
// with the same pairing, gate, freezing, convergence and covariance, over a full rigid motion, so
// roll and pitch are estimated as well instead of taken from gravity. It exists to measure what
// gravity buys the matcher (thesis 6.1: the 4-DoF matcher finds about 40 % more matches).
//
// Parameters: the translation in A's frame and a rotation vector w applied on the left, about
// A's origin (R <- Exp(w) R), so the residual's Jacobian is
//   dr/d(x, y, z) = n,   dr/dw = (R p) x n,
// whose last entry is the 4-DoF yaw's. Covariance (x, y, z, wx, wy, wz) in that order, m and
// rad, as in four_dof_icp.h: sigma^2 (J^T J)^-1. Observability as there, with all three rotations
// taken about the paired points' centroid and scaled by their RMS distance from it.

#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "mapping/matching/icp_options.h"
#include "mapping/matching/point_to_plane_icp.h"

namespace cairn {

using SixDofIcpResult = IcpOutcome<Eigen::Isometry3d, 6>;

class SixDofIcp {
 public:
  explicit SixDofIcp(const IcpOptions& options = {}) : options_(options) {}

  // Aligns `source_b` (submap B's cloud, B's frame) to `target_a` (submap A's cloud, A's frame)
  // starting from `T_a_b_initial`.
  SixDofIcpResult Align(std::span<const Eigen::Vector3d> target_a, std::span<const Eigen::Vector3d> source_b,
                        const Eigen::Isometry3d& T_a_b_initial) const;

 private:
  IcpOptions options_;
};

}  // namespace cairn
