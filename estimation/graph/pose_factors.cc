#include "estimation/graph/pose_factors.h"

namespace cairn {

std::unique_ptr<ceres::Manifold> MakePoseManifold() {
  return std::make_unique<ceres::ProductManifold<ceres::EuclideanManifold<3>, ceres::EigenQuaternionManifold>>();
}

Matrix6d SqrtInformation(const Matrix6d& information) {
  return information.llt().matrixU();
}

AbsolutePositionResidual::AbsolutePositionResidual(const Eigen::Vector3d& z, const Eigen::Matrix3d& information)
    : z_(z), sqrt_info(information.llt().matrixU()) {}

ceres::CostFunction* AbsolutePositionResidual::Create(const Eigen::Vector3d& z, const Eigen::Matrix3d& information) {
  return new ceres::AutoDiffCostFunction<AbsolutePositionResidual, 3, 7>(new AbsolutePositionResidual(z, information));
}

}  // namespace cairn
