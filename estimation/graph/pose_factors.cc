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

GnssPositionResidual::GnssPositionResidual(const Eigen::Vector3d& z_enu, const Eigen::Matrix3d& information,
                                           const Eigen::Vector3d& antenna)
    : z_(z_enu), sqrt_info(information.llt().matrixU()), antenna_(antenna) {}

ceres::CostFunction* GnssPositionResidual::Create(const Eigen::Vector3d& z_enu,
                                                  const Eigen::Matrix3d& information,
                                                  const Eigen::Vector3d& antenna) {
  return new ceres::AutoDiffCostFunction<GnssPositionResidual, 3, 7, 7>(
      new GnssPositionResidual(z_enu, information, antenna));
}

}  // namespace cairn
