#pragma once
// The manifold of the graph's structure landmarks (planes, lines): a pose block (7 doubles, the
// layout of pose_factors.h) moved only by tilting its z axis about its own x and y axes and by
// shifting it along `kShifts` of its own axes from `kFirstShift` on:
//   x ⊞ (rx, ry, s...) = T_x * (Exp(rx, ry, 0), shift).
// A plane (normal z) shifts along z, a line (direction z) along x and y; the other directions
// (spin about z, slides within the plane or along the line) are no variables, so the solver has
// no gauge freedom to wander in. The shift is taken before the tilt, so Minus inverts Plus exactly.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/rotation.h>

#include "estimation/graph/pose_factors.h"
#include "estimation/math/tangent_axes.h"

namespace cairn {

template <int kShifts, int kFirstShift>
struct TiltShiftPlus {
  template <class T>
  bool Plus(const T* x, const T* delta, T* x_plus_delta) const {
    const Eigen::Quaternion<T> q(x[6], x[3], x[4], x[5]);
    const T aa[3] = {delta[0], delta[1], T(0)};
    T wxyz[4];
    ceres::AngleAxisToQuaternion(aa, wxyz);
    const Eigen::Quaternion<T> out = q * Eigen::Quaternion<T>(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
    Eigen::Matrix<T, 3, 1> shift = Eigen::Matrix<T, 3, 1>::Zero();
    for (int i = 0; i < kShifts; ++i) shift[kFirstShift + i] = delta[2 + i];
    const Eigen::Matrix<T, 3, 1> t = Eigen::Matrix<T, 3, 1>(x[0], x[1], x[2]) + q * shift;
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
    for (int i = 0; i < kShifts; ++i) y_minus_x[2 + i] = dt[kFirstShift + i];
    return true;
  }
};

// The landmark frame with z along `z` (normalized) through `point`, x and y its tangent axes.
inline Pose3 TiltShiftFrame(const Eigen::Vector3d& z, const Eigen::Vector3d& point) {
  const Eigen::Vector3d n = z.normalized();
  Eigen::Vector3d u, v;
  TangentAxes(n, &u, &v);
  Eigen::Matrix3d R;
  R << u, v, n;
  return Pose3{point, Eigen::Quaterniond(R).normalized()};
}

}  // namespace cairn
