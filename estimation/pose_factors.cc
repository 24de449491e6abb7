#include "estimation/pose_factors.h"

namespace cairn {

std::unique_ptr<ceres::Manifold> MakePoseManifold() {
  return std::make_unique<ceres::ProductManifold<ceres::EuclideanManifold<3>, ceres::EigenQuaternionManifold>>();
}

Matrix6d SqrtInformation(const Matrix6d& information) {
  return information.llt().matrixU();
}

}  // namespace cairn
