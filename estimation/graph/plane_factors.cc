#include "estimation/graph/plane_factors.h"

#include "estimation/graph/pose_factors.h"
#include "estimation/graph/tilt_shift_manifold.h"
#include "estimation/math/tangent_axes.h"

namespace cairn {

std::unique_ptr<ceres::Manifold> MakePlaneLandmarkManifold() {
  return std::make_unique<ceres::AutoDiffManifold<TiltShiftPlus<1, 2>, 7, 3>>();
}

Pose3 PlaneLandmarkFrame(const Eigen::Vector3d& normal, const Eigen::Vector3d& point) {
  return TiltShiftFrame(normal, point);
}

PlaneObservationResidual::PlaneObservationResidual(const Eigen::Vector4d& plane,
                                                   const Eigen::Matrix3d& information)
    : d_(plane.w()), sqrt_info_(information.llt().matrixU()) {
  TangentAxes(Eigen::Vector3d(plane.head<3>().normalized()), &u_, &v_);
}

ceres::CostFunction* PlaneObservationResidual::Create(const Eigen::Vector4d& plane,
                                                      const Eigen::Matrix3d& information) {
  return new ceres::AutoDiffCostFunction<PlaneObservationResidual, 3, 7, 7>(
      new PlaneObservationResidual(plane, information));
}

Eigen::Vector3d PlaneObservationResidual::Error(const Pose3& T_w_s, const Pose3& T_w_l) const {
  double s[7], l[7];
  PoseToBlock(T_w_s, s);
  PoseToBlock(T_w_l, l);
  Eigen::Vector3d r;
  (*this)(s, l, r.data());
  return sqrt_info_.triangularView<Eigen::Upper>().solve(r);
}

}  // namespace cairn
