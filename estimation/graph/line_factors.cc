#include "estimation/graph/line_factors.h"

#include "estimation/graph/pose_factors.h"
#include "estimation/graph/tilt_shift_manifold.h"
#include "estimation/math/tangent_axes.h"

namespace cairn {

std::unique_ptr<ceres::Manifold> MakeLineLandmarkManifold() {
  return std::make_unique<ceres::AutoDiffManifold<TiltShiftPlus<2, 0>, 7, 4>>();
}

Pose3 LineLandmarkFrame(const Eigen::Vector3d& direction, const Eigen::Vector3d& point) {
  return TiltShiftFrame(direction, point);
}

LineObservationResidual::LineObservationResidual(const Eigen::Vector3d& point,
                                                 const Eigen::Vector3d& direction,
                                                 const Eigen::Matrix4d& information)
    : c_(point), d_(direction.normalized()), sqrt_info_(information.llt().matrixU()) {
  TangentAxes(d_, &u_, &w_);
}

ceres::CostFunction* LineObservationResidual::Create(const Eigen::Vector3d& point,
                                                     const Eigen::Vector3d& direction,
                                                     const Eigen::Matrix4d& information) {
  return new ceres::AutoDiffCostFunction<LineObservationResidual, 4, 7, 7>(
      new LineObservationResidual(point, direction, information));
}

Eigen::Vector4d LineObservationResidual::Error(const Pose3& T_w_s, const Pose3& T_w_l) const {
  double s[7], l[7];
  PoseToBlock(T_w_s, s);
  PoseToBlock(T_w_l, l);
  Eigen::Vector4d r;
  (*this)(s, l, r.data());
  return sqrt_info_.triangularView<Eigen::Upper>().solve(r);
}

}  // namespace cairn
