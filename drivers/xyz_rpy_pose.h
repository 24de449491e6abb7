#pragma once
// A pose as profiles write it: x, y, z (m), then roll, pitch, yaw (rad, applied z-y-x).

#include <vector>

#include <Eigen/Geometry>

namespace cairn {

inline Eigen::Isometry3d PoseFromXyzRpy(const std::vector<double>& v) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  T.linear() = (Eigen::AngleAxisd(v[5], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(v[4], Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(v[3], Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

}  // namespace cairn
