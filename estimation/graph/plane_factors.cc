#include "estimation/graph/plane_factors.h"

#include <ceres/rotation.h>

#include "estimation/graph/pose_factors.h"

namespace cairn {
namespace {

// x ⊞ (rx, ry, tz) = T_x * (Exp(rx, ry, 0), (0, 0, tz)) with the translation taken along the
// landmark's normal before the tilt: Minus inverts it exactly.
struct PlaneLandmarkPlus {
  template <class T>
  bool Plus(const T* x, const T* delta, T* x_plus_delta) const {
    const Eigen::Quaternion<T> q(x[6], x[3], x[4], x[5]);
    const T aa[3] = {delta[0], delta[1], T(0)};
    T wxyz[4];
    ceres::AngleAxisToQuaternion(aa, wxyz);
    const Eigen::Quaternion<T> out = q * Eigen::Quaternion<T>(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
    const Eigen::Matrix<T, 3, 1> t =
        Eigen::Matrix<T, 3, 1>(x[0], x[1], x[2]) + q * Eigen::Matrix<T, 3, 1>(T(0), T(0), delta[2]);
    x_plus_delta[0] = t.x();
    x_plus_delta[1] = t.y();
    x_plus_delta[2] = t.z();
    x_plus_delta[3] = out.x();
    x_plus_delta[4] = out.y();
    x_plus_delta[5] = out.z();
    x_plus_delta[6] = out.w();
    return true;
  }

  template <class T>
  bool Minus(const T* y, const T* x, T* y_minus_x) const {
    const Eigen::Quaternion<T> q_x(x[6], x[3], x[4], x[5]);
    const Eigen::Quaternion<T> q_y(y[6], y[3], y[4], y[5]);
    const Eigen::Matrix<T, 3, 1> log = pose_factors_internal::LogQ<T>(q_x.conjugate() * q_y);
    const Eigen::Matrix<T, 3, 1> dt =
        q_x.conjugate() * Eigen::Matrix<T, 3, 1>(y[0] - x[0], y[1] - x[1], y[2] - x[2]);
    y_minus_x[0] = log.x();
    y_minus_x[1] = log.y();
    y_minus_x[2] = dt.z();
    return true;
  }
};

}  // namespace

std::unique_ptr<ceres::Manifold> MakePlaneLandmarkManifold() {
  return std::make_unique<ceres::AutoDiffManifold<PlaneLandmarkPlus, 7, 3>>();
}

void PlaneTangentAxes(const Eigen::Vector3d& n, Eigen::Vector3d* u, Eigen::Vector3d* v) {
  Eigen::Vector3d h = Eigen::Vector3d::UnitZ().cross(n);
  if (h.squaredNorm() < 0.01) h = Eigen::Vector3d::UnitX() - n.x() * n;
  *u = h.normalized();
  *v = n.cross(*u);
}

Pose3 PlaneLandmarkFrame(const Eigen::Vector3d& normal, const Eigen::Vector3d& point) {
  const Eigen::Vector3d n = normal.normalized();
  Eigen::Vector3d u, v;
  PlaneTangentAxes(n, &u, &v);
  Eigen::Matrix3d R;
  R << u, v, n;
  return Pose3{point, Eigen::Quaterniond(R).normalized()};
}

PlaneObservationResidual::PlaneObservationResidual(const Eigen::Vector4d& plane,
                                                   const Eigen::Matrix3d& information)
    : d_(plane.w()), sqrt_info_(information.llt().matrixU()) {
  PlaneTangentAxes(plane.head<3>().normalized(), &u_, &v_);
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
