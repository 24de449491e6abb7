#pragma once
// Whitened 3-D difference of one stereo point pair for the pose refinement:
// W (R p_cur + t - p_kf), W = L^-1 with L L^T the pair's combined covariance. Analytic Jacobians
// (autodiff through 7 dual numbers cost more than the solve). Parameters: the quaternion
// (x, y, z, w, as Eigen stores it) on ceres::EigenQuaternionManifold, and t.

#include <ceres/sized_cost_function.h>
#include <Eigen/Core>

namespace cairn {

class PointPairResidual : public ceres::SizedCostFunction<3, 4, 3> {
 public:
  PointPairResidual(const Eigen::Vector3d& kf, const Eigen::Vector3d& cur, const Eigen::Matrix3d& whiten)
      : kf_(kf), cur_(cur), whiten_(whiten) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Eigen::Vector3d kf_, cur_;
  Eigen::Matrix3d whiten_;
};

}  // namespace cairn
