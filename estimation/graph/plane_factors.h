#pragma once
// Plane landmarks in the SLAM graph (paper 003's planar faces as landmarks l, observed by the
// submaps o that see them). A plane landmark is stored as a pose block (7 doubles, the layout of
// pose_factors.h) whose x-y plane is the plane: its z axis is the normal and its origin a point of
// the plane. A plane has three degrees of freedom, so the block lives on PlaneLandmarkManifold, whose
// tangent (rx, ry, tz) tilts the normal about the frame's own x and y axes and moves the plane
// along it; the rotation about the normal and the slide within the plane are no variables at all
// (no gauge freedom for the solver to wander in).
//
// Observation residual of a submap s (pose T_w_s) seeing landmark l (T_w_l), measured as the plane
// n . p + d = 0 in s with covariance C of (a, b, d) in SubmapPlane's tangent axes (u, v) of n:
//   n_s = R_s^T R_l e_z,  d_s = -n_s . R_s^T (t_l - t_s),
//   r = sqrt(C^-1) [u . n_s; v . n_s; d_s - d].

#include <memory>

#include <Eigen/Core>
#include <ceres/ceres.h>

#include "estimation/graph/pose_graph.h"

namespace cairn {

std::unique_ptr<ceres::Manifold> MakePlaneLandmarkManifold();

// The landmark frame of the plane through `point` with unit normal `normal` (its x axis level
// where the plane is not, as SubmapPlane's u axis).
Pose3 PlaneLandmarkFrame(const Eigen::Vector3d& normal, const Eigen::Vector3d& point);

class PlaneObservationResidual {
 public:
  // `plane` = (n, d) measured in the submap's frame; `information` of (a, b, d).
  PlaneObservationResidual(const Eigen::Vector4d& plane, const Eigen::Matrix3d& information);
  static ceres::CostFunction* Create(const Eigen::Vector4d& plane, const Eigen::Matrix3d& information);

  template <class T>
  bool operator()(const T* submap, const T* landmark, T* residual) const;

  // The unwhitened error (a, b, d) of the poses T_w_s and T_w_l.
  Eigen::Vector3d Error(const Pose3& T_w_s, const Pose3& T_w_l) const;

 private:
  Eigen::Vector3d u_, v_;
  double d_ = 0.0;
  Eigen::Matrix3d sqrt_info_;
};

template <class T>
bool PlaneObservationResidual::operator()(const T* submap, const T* landmark, T* residual) const {
  const Eigen::Quaternion<T> q_s(submap[6], submap[3], submap[4], submap[5]);
  const Eigen::Quaternion<T> q_l(landmark[6], landmark[3], landmark[4], landmark[5]);
  const Eigen::Matrix<T, 3, 1> t_s(submap[0], submap[1], submap[2]);
  const Eigen::Matrix<T, 3, 1> t_l(landmark[0], landmark[1], landmark[2]);
  const Eigen::Quaternion<T> q_s_inv = q_s.conjugate();
  // Both manifolds keep the quaternions unit.
  const Eigen::Matrix<T, 3, 1> n_s = q_s_inv * (q_l * Eigen::Matrix<T, 3, 1>(T(0), T(0), T(1)));
  const Eigen::Matrix<T, 3, 1> p_s = q_s_inv * (t_l - t_s);
  const T d_s = -n_s.dot(p_s);
  Eigen::Matrix<T, 3, 1> e(u_.cast<T>().dot(n_s), v_.cast<T>().dot(n_s), d_s - T(d_));
  Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
  r = sqrt_info_.cast<T>() * e;
  return true;
}

}  // namespace cairn
