#pragma once
// Line landmarks in the SLAM graph (paper 000's straight edges as landmarks l, observed by the
// submaps o that see them). A line landmark is stored as a pose block (7 doubles, the layout of
// pose_factors.h) whose z axis is the line: the z axis is its direction and the origin a point of
// it. A line has four degrees of freedom, so the block lives on LineLandmarkManifold, whose
// tangent (rx, ry, tx, ty) tilts the direction about the frame's own x and y axes and moves the line
// perpendicular to itself; the rotation about the line and the slide along it are no variables at
// all (no gauge freedom for the solver to wander in).
//
// Observation residual of a submap s (pose T_w_s) seeing landmark l (T_w_l), measured as a point c
// and a unit direction d of the line in s, with covariance C of the error e below in the tangent
// axes (u, w) of d (tangent_axes.h):
//   v_s = R_s^T R_l e_z,  p_s = R_s^T (t_l - t_s),
//   c' = p_s + ((c - p_s) . v_s) v_s      (the landmark's point closest to c),
//   e = [u . v_s; w . v_s; u . (c' - c); w . (c' - c)],  r = sqrt(C^-1) e.
// An edge has no orientation: v_s is taken with the sign that agrees with d, so e is the same for
// a landmark and its reverse (c' does not depend on the sign at all; the direction components would
// only flip), and neither the caller nor the solver keeps any sign bookkeeping.

#include <memory>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/ceres.h>

#include "estimation/graph/pose_graph.h"

namespace cairn {

std::unique_ptr<ceres::Manifold> MakeLineLandmarkManifold();

// The landmark frame of the line through `point` along `direction`: z the normalized direction, x
// and y its tangent axes (u, v of TangentAxes).
Pose3 LineLandmarkFrame(const Eigen::Vector3d& direction, const Eigen::Vector3d& point);

class LineObservationResidual {
 public:
  // `point` (the segment's middle) and unit `direction` measured in the submap's frame;
  // `information` of e.
  LineObservationResidual(const Eigen::Vector3d& point, const Eigen::Vector3d& direction,
                          const Eigen::Matrix4d& information);
  static ceres::CostFunction* Create(const Eigen::Vector3d& point, const Eigen::Vector3d& direction,
                                     const Eigen::Matrix4d& information);

  template <class T>
  bool operator()(const T* submap, const T* landmark, T* residual) const;

  // The unwhitened error e of the poses T_w_s and T_w_l.
  Eigen::Vector4d Error(const Pose3& T_w_s, const Pose3& T_w_l) const;

 private:
  Eigen::Vector3d c_, d_, u_, w_;
  Eigen::Matrix4d sqrt_info_;
};

template <class T>
bool LineObservationResidual::operator()(const T* submap, const T* landmark, T* residual) const {
  using V3 = Eigen::Matrix<T, 3, 1>;
  const Eigen::Quaternion<T> q_s(submap[6], submap[3], submap[4], submap[5]);
  const Eigen::Quaternion<T> q_l(landmark[6], landmark[3], landmark[4], landmark[5]);
  const V3 t_s(submap[0], submap[1], submap[2]);
  const V3 t_l(landmark[0], landmark[1], landmark[2]);
  const Eigen::Quaternion<T> q_s_inv = q_s.conjugate();
  // Both manifolds keep the quaternions unit.
  V3 v_s = q_s_inv * (q_l * V3(T(0), T(0), T(1)));
  // The sign is constant near any solution (the directions are far from perpendicular there).
  if (d_.cast<T>().dot(v_s) < T(0)) v_s = -v_s;
  const V3 p_s = q_s_inv * (t_l - t_s);
  const V3 c = c_.cast<T>();
  const V3 offset = p_s + (c - p_s).dot(v_s) * v_s - c;
  const V3 u = u_.cast<T>(), w = w_.cast<T>();
  const Eigen::Matrix<T, 4, 1> e(u.dot(v_s), w.dot(v_s), u.dot(offset), w.dot(offset));
  Eigen::Map<Eigen::Matrix<T, 4, 1>> r(residual);
  r = sqrt_info_.cast<T>() * e;
  return true;
}

}  // namespace cairn
