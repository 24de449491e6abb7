#pragma once
// A straight edge triangulated in one stereo image: its two ends with their errors (eq. 5.2
// through the edge's fit, so the ends' errors are correlated) and the camera centre it was seen
// from, all in one frame (the camera's as triangulated, the submap's once placed).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cairn {

struct LineSighting {
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();  // endpoints, m
  Eigen::Matrix3d cov_a = Eigen::Matrix3d::Identity(), cov_b = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d cov_ab = Eigen::Matrix3d::Zero();     // E[(a error)(b error)^T]
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();  // camera centre, m

  // The same sighting in frame f, given T_f_this.
  LineSighting Transformed(const Eigen::Isometry3d& T) const {
    const Eigen::Matrix3d R = T.rotation();
    LineSighting s;
    s.a = T * a;
    s.b = T * b;
    s.cov_a = R * cov_a * R.transpose();
    s.cov_b = R * cov_b * R.transpose();
    s.cov_ab = R * cov_ab * R.transpose();
    s.viewpoint = T * viewpoint;
    return s;
  }
};

}  // namespace cairn
