#pragma once
// Analytic Ceres cost functions of the pose factors in pose_factors.h (same residuals; the
// templated functors there stay the reference, checked against these in the tests). Autodiff of
// the geodesic error through 14 dual numbers dominated every graph solve; these evaluate the
// tangent-space Jacobian in closed form instead.
//
// The Jacobians are valid on PoseManifold() only: Ceres multiplies the 7-column Jacobian by the
// manifold's PlusJacobian P, so the quaternion columns are J_tangent * pinv(dq/dtangent) (exact:
// P has orthogonal columns), which gives J_tangent back.

#include <ceres/sized_cost_function.h>

#include "estimation/graph/pose_graph.h"

namespace cairn {

// r = S [R_ij^T (R_i^T (t_j - t_i) - t_ij); Log(R_ij^T R_i^T R_j)], S^T S = information.
class RelativePoseCost final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  RelativePoseCost(const Pose3& T_i_j, const Matrix6d& information);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Eigen::Vector3d t_ij_;
  Eigen::Quaterniond q_ji_;
  Matrix6d sqrt_info_;
};

// r = [sqrt(tau) (R_i^T (t_j - t_i) - t_ij); sqrt(8 kappa) vec(q_ij^-1 q_i^-1 q_j)] (w >= 0), whose
// squared norm is the SE-Sync term (see ChordalResidual).
class ChordalCost final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  ChordalCost(const Pose3& T_i_j, double kappa, double tau);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Eigen::Vector3d t_ij_;
  Eigen::Quaterniond q_ji_;
  double sqrt_8kappa_, sqrt_tau_;
};

// r = S [R_z^T (t - t_z); Log(R_z^T R)].
class AbsolutePoseCost final : public ceres::SizedCostFunction<6, 7> {
 public:
  AbsolutePoseCost(const Pose3& Z, const Matrix6d& information);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Eigen::Vector3d t_;
  Eigen::Quaterniond q_inv_;
  Matrix6d sqrt_info_;
};

}  // namespace cairn
